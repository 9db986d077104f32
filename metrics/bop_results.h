// BOP's result format (bop_toolkit docs/bop_challenge_2019.md, "Format of results"), the CSV that
// published methods submit: one line per estimate,
//
//   scene_id,im_id,obj_id,score,R,t,time
//
// R: the rotation of camera_T_object, 9 numbers row-major separated by spaces; t: its translation
// in millimetres, 3 numbers; score: the method's confidence; time: seconds the method took for the
// whole image (-1: not measured). A header line "scene_id,im_id,..." is optional on reading and
// always written.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/rigid3.h"

namespace mmh::metrics {

struct BopResult {
  int scene_id = 0;
  int im_id = 0;
  int obj_id = 0;
  double score = 1.0;
  Rigid3 camera_T_object;  // [m]
  double time = -1.0;      // [s]
};

// Reads a result file. A line with another number of fields, a field that is not a number (or
// not an integer id), R not a rotation (orthonormal to 1e-3, determinant +1): InputError naming the
// file, the line and the field.
std::vector<BopResult> ReadBopResults(const std::filesystem::path& path);

// The scene id of a recording folder named by a number (BOP's scene 000048, YCB-Video's video
// 0000), or nullopt.
std::optional<int> SceneIdOfFolder(const std::filesystem::path& folder);

// The file's text, header first (R to 9 significant digits, t in mm to 1e-6).
std::string FormatBopResults(const std::vector<BopResult>& results);

}  // namespace mmh::metrics
