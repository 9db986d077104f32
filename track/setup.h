// The setup-time calibration the tracker may use, as a user of the real system marks it once
// before recording (never per-frame ground truth): where the play area and the Like box are on the
// table, and optionally the camera's pose above the table. mmh render writes it as scene.json;
// for a real Kinect the user writes the same keys (docs/tracker.md).
//
// The table plane itself is estimated from the frames (track/table_plane.h); camera_T_table, when
// given, only fixes the origin and the in-plane axes of the table frame (the tape marks) and
// selects which plane is the table.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/rigid3.h"

namespace mmh::track {

struct TrackSetup {
  // Pose of the table frame (z up, origin at the play area's centre on the table top, x right as
  // the camera sees it) in the depth camera's frame; nullopt: the tracker derives it from the
  // estimated plane (origin where the optical axis meets it, x along the camera's x).
  std::optional<Rigid3> camera_T_table;
  // The taped play area, centred on the table frame's origin [m].
  double play_area_width = 0.40;  // along x
  double play_area_depth = 0.30;  // along y
  // The Like box [m]: centre in the table frame, length along x (-5 at its -x end, +5 at its +x
  // end), width along y. Without a Like box (like_box_length = 0) the slider is not read.
  double like_box_center_x = 0.36;
  double like_box_center_y = -0.05;
  double like_box_length = 0.16;
  double like_box_width = 0.06;
  // Edge length of the (square) green slider block [m]; its centre travels between the positions
  // where it touches the box's ends.
  double slider_block_size = 0.0318;

  bool has_like_box() const { return like_box_length > 0; }
  // Positive finite sizes, a block shorter than the box; InputError naming `where`.
  void Validate(const std::string& where) const;
};

// Reads scene.json as mmh render writes it: "camera_T_table" {"translation": [3],
// "quaternion_xyzw": [4]} (optional), "table" {"play_area_width", "play_area_depth",
// "like_box_center_x", "like_box_center_y", "like_box_length", "like_box_width", ...} (other keys
// of the renderer's scene options are ignored), "slider_block_size" (optional). Missing required
// keys, wrong types, non-finite values and a non-unit quaternion are InputErrors naming the file
// and the key.
TrackSetup ReadSetupJson(const std::filesystem::path& path);

}  // namespace mmh::track
