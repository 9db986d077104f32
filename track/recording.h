// Real recordings with per-frame 6-DoF ground truth of known objects, as the public pose
// benchmarks publish them (DESIGN.md, "File formats"), read as a FrameSource plus the truth:
//
// - a BOP scene folder (Hodan et al. 2018; bop_toolkit docs/bop_datasets_format.md):
//   scene_camera.json ({"<im_id>": {"cam_K": [9], "depth_scale": mm per unit}}), scene_gt.json
//   ({"<im_id>": [{"cam_R_m2c": [9], "cam_t_m2c": [3, mm], "obj_id": N}]}), optional
//   scene_gt_info.json (one entry per ground-truth pose, in the same order), rgb/ (or gray/) and
//   depth/ images named <im_id:06d>.png (or .jpg / .tif);
// - a YCB-Video video folder (Xiang et al. 2018): <frame:06d>-color.png, <frame>-depth.png and
//   <frame>-meta.mat (MATLAB v5: intrinsic_matrix, factor_depth units per metre, poses 3x4xN
//   camera_T_object in metres, cls_indexes N) or its plain-text export <frame>-meta.txt
//   (track/mat_file.h).
//
// Intrinsics and the depth scale always come from the dataset's own files, per frame; a frame
// without them, ground truth that does not match the images (an image without an entry, an
// entry without an image, scene_gt_info.json of another length, a rotation that is not one) is an
// InputError naming the file, the frame and the value. Frames have no timestamps in either
// format: frame k of the folder is at im_id / frame_rate seconds.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/trajectory.h"
#include "track/frame_source.h"

namespace mmh::track {

enum class RecordingLayout { kBop, kYcbVideo };
const char* RecordingLayoutName(RecordingLayout layout);

// The layout of `folder`, or nullopt when it is neither (e.g. a TUM RGB-D folder).
std::optional<RecordingLayout> DetectRecordingLayout(const std::filesystem::path& folder);

struct ObjectTruth {
  // BOP obj_id, or YCB-Video's class index (1-based row of classes.txt).
  int object_id = 0;
  Rigid3 camera_T_object;  // [m]
  // Share of the object's silhouette that is visible (BOP scene_gt_info.json's visib_fract), or
  // -1 when the dataset does not say.
  double visible_fraction = -1.0;
};

struct RecordingFrameInfo {
  int image_id = 0;  // BOP im_id, YCB-Video frame number
  std::filesystem::path depth_file;
  std::filesystem::path color_file;  // empty when the frame has none
  PinholeIntrinsics intrinsics;      // of the registered depth and colour images
  double depth_scale = 0.0;          // metres per depth unit
  std::vector<ObjectTruth> truth;
};

class RecordingFrameSource : public FrameSource {
 public:
  // Reads every frame's camera and ground truth (not the images) and checks them; the image
  // size comes from the first depth image. frame_rate [Hz] > 0 gives the timestamps.
  explicit RecordingFrameSource(const std::filesystem::path& folder, double frame_rate = 30.0);

  bool Next(RgbdFrame* frame) override;
  std::string Describe() const override;
  int size() const override { return static_cast<int>(frames_.size()); }

  RecordingLayout layout() const { return layout_; }
  const std::vector<RecordingFrameInfo>& frames() const { return frames_; }
  // Every object id with ground truth in some frame, increasing.
  std::vector<int> object_ids() const;
  // The object's ground truth over the frames that annotate it (one instance per frame: a
  // second instance of the same id is an InputError naming the frame), timestamps as Next's.
  Trajectory Truth(int object_id) const;
  double timestamp(int k) const { return frames_.at(k).image_id / frame_rate_; }

 private:
  void ReadBop();
  void ReadYcbVideo();

  std::filesystem::path folder_;
  RecordingLayout layout_;
  double frame_rate_;
  std::vector<RecordingFrameInfo> frames_;
  int next_ = 0;
};

// A camera_T_object from BOP's row-major cam_R_m2c and cam_t_m2c [mm]; a matrix that is not a
// rotation (orthonormal to 1e-3, determinant +1) or non-finite values are an InputError naming
// `where`.
Rigid3 PoseFromRowMajor(const double r[9], const double t[3], double t_to_metres,
                        const std::string& where);

}  // namespace mmh::track
