// Reads the slider: the green block in the Like box, found by colour (HSV, OpenCV) and depth (its
// points above the table inside the box), its centre along the box's long axis mapped to -5..+5 by
// the Like box's calibration (track/setup.h): value = 5 (x - centre_x) / ((length - block) / 2).
//
// The block's centre is the middle of its extent along the box (robust quantiles of its points'
// table-frame x): the camera sees one side face and the top, whose points span the block's full
// length, so the middle is unbiased where a centroid of the visible points is not. Per image row,
// green pixels without depth take the depth of the nearest block point in their run of green (the
// colour camera sees the block where the IR camera or the projector does not), and points much
// nearer than the row's others (an occluding finger's depth spread by the block matcher) are
// dropped; a hand hiding one end only is corrected for (docs/tracker.md, "Slider").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "track/setup.h"

namespace mmh::track {

struct SliderReaderOptions {
  // Green in OpenCV's HSV (hue 0..180): hue in [hue_min, hue_max], saturation and value at least.
  int hue_min = 35;
  int hue_max = 90;
  int saturation_min = 70;
  int value_min = 25;
  // Block points lie between min_height and the block's size plus max_height_margin above the
  // table [m], inside the Like box grown by box_margin [m].
  double min_height = 0.004;
  double max_height_margin = 0.01;
  double box_margin = 0.02;
  // The extent along the box: the quantiles edge_quantile and 1 - edge_quantile of the points' x.
  double edge_quantile = 0.02;
  // A reading needs this many block points.
  int min_points = 15;
  // Green pixels without depth in a row's run of green take the depth of the run's nearest block
  // point, so that the extent is the colour image's (see slider_reader.cc).
  bool fill_missing_depth = true;
  // A row's block points lie within depth_margin [m] of its upper quartile of depth; nearer ones
  // hold an occluder's depth (a finger's, spread by the block matcher).
  double depth_margin = 0.01;

  template <class V>
  void VisitFields(V& v) {
    v("hue_min", hue_min);
    v("hue_max", hue_max);
    v("saturation_min", saturation_min);
    v("value_min", value_min);
    v("min_height", min_height);
    v("max_height_margin", max_height_margin);
    v("box_margin", box_margin);
    v("edge_quantile", edge_quantile);
    v("min_points", min_points);
    v("fill_missing_depth", fill_missing_depth);
    v("depth_margin", depth_margin);
  }
  void Validate(const std::string& prefix) const;
};

struct SliderReading {
  bool found = false;
  // In [-5, 5] (clamped) when found.
  double value = 0.0;
  // Unclamped value and the block's centre x in the table frame [m].
  double raw_value = 0.0;
  double center_x = 0.0;
  int points = 0;
  std::string reason;  // why not found
};

class SliderReader {
 public:
  // The setup must have a Like box (InputError otherwise). Options validated (prefix "slider").
  SliderReader(const TrackSetup& setup, const SliderReaderOptions& options);

  // Reads one frame given the table frame in its depth camera. A frame without registered colour
  // or of the wrong size gives found = false with the reason.
  SliderReading Read(const RgbdFrame& frame, const Rigid3& camera_T_table);

 private:
  // A block point: pixel, camera depth [m] and table x, y [m].
  struct BlockPoint {
    int u, v;
    float z, x, y;
  };
  TrackSetup setup_;
  SliderReaderOptions options_;
  std::vector<BlockPoint> points_;
  std::vector<float> xs_;
  std::vector<float> row_z_;
};

}  // namespace mmh::track
