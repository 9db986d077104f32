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
#include "core/table_setup.h"

namespace mmh::track {

// The table's calibration (play area, Like box, slider block; core/table_setup.h) and, optionally,
// where the camera stands.
struct TrackSetup : TableSetup {
  // Pose of the table frame (z up, origin at the play area's centre on the table top, x right as
  // the camera sees it) in the depth camera's frame; nullopt: the tracker derives it from the
  // estimated plane (origin where the optical axis meets it, x along the camera's x).
  std::optional<Rigid3> camera_T_table;

  // TableSetup::Validate and a finite camera_T_table with a unit quaternion; InputError naming
  // `where`.
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
