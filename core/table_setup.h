// The table's calibration, as the user of the real system marks it once with tape before recording
// (the paper's Figure 1: a Play area and a Like box whose green block is a -5..+5 slider): where
// the play area and the Like box lie in the table frame, and the size of the slider block that
// moves in the Like box. The renderer builds its scene from it (sim::TableSceneOptions), the
// tracker reads the slider with it (track::TrackSetup), and the simulated people act inside its
// play area.
//
// Table frame (docs/notation.md): z up, origin at the centre of the play area on the table top, x
// to the right as the camera sees it, y away from the camera.
#pragma once

#include <string>

namespace mmh {

struct TableSetup {
  // The taped play area [m], centred on the table frame's origin.
  double play_area_width = 0.40;  // along x
  double play_area_depth = 0.30;  // along y
  // The Like box [m]: a taped rectangle beside the play area; the slider block slides along its
  // long axis (x), -5 (dislike) at its -x end, +5 (like) at its +x end. Without a Like box
  // (like_box_length = 0) there is no slider.
  double like_box_center_x = 0.36;
  double like_box_center_y = -0.05;
  double like_box_length = 0.16;  // along x
  double like_box_width = 0.06;   // along y
  // Edge length of the square green slider block [m] (a 2x2 Duplo brick, 31.8 mm).
  double slider_block_size = 0.0318;

  bool has_like_box() const { return like_box_length > 0; }

  // How far the block's centre travels from the box's centre to either end [m]: it stops where its
  // edge touches the box's end.
  double SliderTravel() const { return 0.5 * (like_box_length - slider_block_size); }
  // The slider formula, written once: the block's centre x for slider value `value` (linear,
  // -5 at one end of its travel, +5 at the other) ...
  double SliderCenterX(double value) const {
    return like_box_center_x + value / 5.0 * SliderTravel();
  }
  // ... and its inverse, not clamped (a block pushed beyond the box's ends reads beyond +-5).
  double SliderValue(double center_x) const {
    return 5.0 * (center_x - like_box_center_x) / SliderTravel();
  }

  // Positive finite play area and block, finite Like box centre, a non-negative Like box length;
  // with a Like box, a positive width and a length greater than the block. InputErrors name
  // where + "." + field.
  void Validate(const std::string& where) const;
};

}  // namespace mmh
