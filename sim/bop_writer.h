// BOP ground truth (Hodan et al., BOP: Benchmark for 6D Object Pose Estimation; format of the
// bop_toolkit, docs/bop_datasets_format.md), so that pose-estimation tools can score on rendered
// sequences:
//
//   scene_gt.json      {"<im_id>": [{"cam_R_m2c": [9, row-major], "cam_t_m2c": [3, mm],
//                                    "obj_id": N}, ...], ...}
//   scene_camera.json  {"<im_id>": {"cam_K": [9, row-major], "depth_scale": mm per depth unit}}
//
// im_id is the frame index from 0; cam_R_m2c and cam_t_m2c map model to camera coordinates (our
// camera_T_object, translation in millimetres). Keys are written in increasing im_id, one image
// per line (as bop_toolkit's save_json), numbers in shortest round-trip form; files are written
// atomically.
#pragma once

#include <filesystem>
#include <vector>

#include "core/camera.h"
#include "core/rgbd_frame.h"
#include "core/rigid3.h"

namespace mmh::sim {

struct BopObjectPose {
  // BOP object id (>= 1; the model file obj_<id:06d>.ply).
  int obj_id = 1;
  // Object model coordinates to camera coordinates [m].
  Rigid3 camera_T_object;
};

// Per frame, the visible (or all) objects' poses. frames[i] is image i.
using BopFrames = std::vector<std::vector<BopObjectPose>>;

// scene_gt.json. An obj_id < 1 or a non-finite pose is an InputError naming the frame.
void WriteBopSceneGt(const std::filesystem::path& path, const BopFrames& frames);

// scene_camera.json for `frame_count` images of one camera; depth_scale_m is metres per depth
// unit (TUM: 1/5000, written as BOP's 0.2 mm per unit).
void WriteBopSceneCamera(const std::filesystem::path& path, const PinholeIntrinsics& intrinsics,
                         int frame_count, double depth_scale_m = kTumDepthScale);

// Both files into `scene_folder` (created when missing).
void WriteBopScene(const std::filesystem::path& scene_folder, const BopFrames& frames,
                   const PinholeIntrinsics& intrinsics, double depth_scale_m = kTumDepthScale);

}  // namespace mmh::sim
