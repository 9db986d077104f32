// RGB-D sequences as folders in the TUM RGB-D benchmark layout (DESIGN.md, "File formats"):
//
//   rgb/<timestamp>.png     8-bit RGB
//   depth/<timestamp>.png   16-bit, depth_scale metres per unit (TUM: 5000 = 1 m), 0 = missing
//   rgb.txt, depth.txt      '# ' header lines, then 'timestamp filename' per frame
//   groundtruth.txt         optional TUM trajectory (here: camera_T_proxy of the simulator)
//   camera.json             intrinsics, depth_scale, color_T_depth, sensor description
//
// Timestamps are written with 6 decimals, as TUM does; they read back exactly when they are whole
// microseconds (t = k / 1e6, which a 30 Hz simulator can choose), otherwise rounded to the
// microsecond. Images read back bit-identical.
//
// The reader also opens public TUM RGB-D sequences (no camera.json): the intrinsics then come from
// an explicit argument or from 'freiburg1/2/3' in the folder name.
//
// The writer stages its folder (core/staged_folder.h, the all-or-nothing rule of every mmh output
// folder).
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/camera.h"
#include "core/image_io.h"
#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/staged_folder.h"
#include "core/trajectory.h"

namespace mmh {

// What camera.json holds besides bookkeeping.
struct RgbdCameraInfo {
  PinholeIntrinsics depth_intrinsics;
  PinholeIntrinsics color_intrinsics;
  // Metres per depth unit [m]; the TUM format's 1/5000.
  double depth_scale = kTumDepthScale;
  // Pose of the depth camera in the colour camera's frame (identity: registered depth).
  Rigid3 color_T_depth;
  // Free-form description of the sensor (e.g. the Kinect calibration and noise options); an
  // object or null.
  nlohmann::json sensor = nlohmann::json::object();
  // zlib level of the PNGs a writer makes (not stored in camera.json): 1 writes about 3.5 times
  // faster than the default 6 for files 5-15 % larger; the pixels are the same.
  int png_compression = kDefaultPngCompression;

  // Intrinsics valid, depth_scale finite and > 0, unit quaternion; InputError naming `prefix`.
  void Validate(const std::string& prefix) const;
};

// Published calibration of the TUM RGB-D sequences (https://cvg.cit.tum.de/data/datasets/
// rgbd-dataset/file_formats): 'freiburg1', 'freiburg2' or 'freiburg3' anywhere in `folder_name`
// selects fr1 517.3/516.5/318.6/255.3, fr2 520.9/521.0/325.1/249.7, fr3 535.4/539.2/320.1/247.6
// (640x480, depth registered to colour, 5000 units = 1 m); nullopt for other names.
std::optional<RgbdCameraInfo> TumCameraInfoFromName(const std::string& folder_name);

// Writes one sequence through a StagedFolder: Finish() moves it into place, a writer destroyed
// without Finish() leaves nothing. An existing target is replaced only when it is empty or mmh
// wrote it (camera.json with "writer": "mmh"); otherwise InputError naming it.
//
// Add() may be called from several threads at once (frames are encoded in parallel); the lists
// are sorted by timestamp in Finish().
class RgbdFolderWriter {
 public:
  RgbdFolderWriter(const std::filesystem::path& target, const RgbdCameraInfo& camera);
  ~RgbdFolderWriter();
  RgbdFolderWriter(const RgbdFolderWriter&) = delete;
  RgbdFolderWriter& operator=(const RgbdFolderWriter&) = delete;

  // Writes the frame's images into the staging folder. Its sizes, intrinsics and depth_scale must
  // match the camera info and its timestamp must be finite, >= 0 and differ from every other
  // frame's at 6 decimals: otherwise an InputError naming the frame index.
  void Add(const RgbdFrame& frame);

  // Writes the lists, groundtruth.txt (when given) and camera.json (with `extra` under "extra"),
  // then moves the staging folder into place. At least one frame must have been added.
  void Finish(const std::optional<Trajectory>& groundtruth = std::nullopt,
              const nlohmann::json& extra = nlohmann::json::object());

  const std::filesystem::path& target() const { return folder_.target(); }
  const std::filesystem::path& staging() const { return folder_.staging(); }

  // The images of every frame added so far, in timestamp order: (depth, rgb) paths relative to
  // staging(), e.g. "depth/0.033333.png". For a second index of the same files before Finish()
  // (the BOP scene of `mmh render`).
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> AddedImages() const;

 private:
  struct Shared;  // the frame list and its mutex

  StagedFolder folder_;
  RgbdCameraInfo camera_;
  std::unique_ptr<Shared> shared_;
};

// Reads a folder written by RgbdFolderWriter, or a public TUM RGB-D sequence.
class RgbdFolderReader {
 public:
  // `intrinsics`, when given, overrides camera.json / the freiburg name for both cameras (for
  // TUM-layout folders of other sensors). Without camera.json, an explicit intrinsics or a
  // 'freiburg1/2/3' folder name is required (then depth_scale = 1/5000, identity color_T_depth).
  explicit RgbdFolderReader(const std::filesystem::path& folder,
                            const std::optional<PinholeIntrinsics>& intrinsics = std::nullopt);

  // Number of associated (rgb, depth) pairs.
  int size() const { return static_cast<int>(pairs_.size()); }

  // Frame i (0 <= i < size()): index i, the depth image's timestamp, both images, the camera info.
  // Missing or unreadable images and size mismatches are InputErrors naming the file.
  RgbdFrame Read(int i) const;

  // Timestamps of the associated pair i [s].
  double depth_timestamp(int i) const { return pairs_.at(i).depth_timestamp; }
  double rgb_timestamp(int i) const { return pairs_.at(i).rgb_timestamp; }

  const RgbdCameraInfo& camera() const { return camera_; }
  // camera.json's "extra" object (empty when absent).
  const nlohmann::json& extra() const { return extra_; }
  const std::filesystem::path& folder() const { return folder_; }

  // groundtruth.txt, when the folder has one.
  std::optional<Trajectory> ReadGroundtruth() const;

 private:
  struct Pair {
    double rgb_timestamp;
    std::filesystem::path rgb_file;
    double depth_timestamp;
    std::filesystem::path depth_file;
  };

  std::filesystem::path folder_;
  RgbdCameraInfo camera_;
  nlohmann::json extra_ = nlohmann::json::object();
  std::vector<Pair> pairs_;
};

// Largest timestamp difference [s] at which an rgb and a depth entry are associated, as the TUM
// tools' associate.py (--max_difference 0.02).
inline constexpr double kRgbdMaxTimeDifference = 0.02;

// TUM's associate.py: all (rgb, depth) pairs closer than `max_difference` seconds, taken greedily
// by increasing difference with each entry used at most once, returned as (rgb index, depth index)
// sorted by rgb timestamp.
std::vector<std::pair<int, int>> AssociateTimestamps(const std::vector<double>& rgb,
                                                     const std::vector<double>& depth,
                                                     double max_difference);

}  // namespace mmh
