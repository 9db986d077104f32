// Segmentation of the proxy's points in a depth frame (DuploTrack-style, Gupta et al. 2012): the
// play-area volume above the estimated table plane, minus a per-pixel background model of what
// stands still, minus the animator's hand by skin colour (YCrCb box, Chai and Ngan 1999; OpenCV),
// split into connected components (OpenCV) of which small ones are dropped as noise.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "track/setup.h"

namespace mmh::track {

struct SegmentationOptions {
  // Every pixel_step-th pixel and row of the play area's image is examined [px].
  int pixel_step = 1;
  // The play volume: the play area grown by play_area_margin [m] on each side, from min_height
  // (above the table's noise and the tape) to max_height above the table plane [m].
  double play_area_margin = 0.03;
  double min_height = 0.008;
  double max_height = 0.30;
  // Background model: a pixel whose depth stays within background_tolerance [m] of its running
  // mean for background_frames frames becomes background; foreground needs to be nearer than the
  // background by background_margin [m]. Pixels covered by the tracked proxy are not learnt.
  bool background = true;
  int background_frames = 90;
  // The background learns from every background_interval-th frame (it changes slowly).
  int background_interval = 4;
  double background_tolerance = 0.01;
  double background_margin = 0.02;
  // Skin: colour in the YCrCb box (Chai and Ngan 1999, Cr 133..173, Cb 77..127). Skin pixels are
  // kept apart: the tracker uses them only where they lie on the proxy's model (a skin-coloured
  // head), so the hand holding the proxy does not pull it.
  bool skin = true;
  int skin_cr_min = 133;
  int skin_cr_max = 173;
  int skin_cb_min = 77;
  int skin_cb_max = 127;
  // The hand's depth reaches past its colour outline where a block matcher's window straddles it
  // (bleed, docs/sensor.md, "The object's outline"): those pixels carry the hand's depth and the
  // background's colour, join the proxy's candidates and pull the detection towards the hand.
  // With skin_grow_px > 0 a candidate touching a skin pixel (8-neighbourhood) whose depth lies
  // within skin_grow_depth [m] of its own becomes skin, skin_grow_px times over. 0: off, for
  // frames without bleed (sensor.mode "statistical"), where the growth only eats the proxy's
  // pixels beside the gripping fingers (docs/tracker.md, "Judged by the interior").
  int skin_grow_px = 1;
  double skin_grow_depth = 0.01;
  // Connected components (8-neighbourhood of foreground pixels) with fewer pixels are dropped.
  int min_component_pixels = 25;
  // Neighbouring pixels belong to one component only when their depths differ by at most
  // max_depth_jump [m] (0: any depth, the image's connectivity alone). On a real cluttered table
  // objects touch in the image without touching in space (a box standing in front of a keyboard):
  // without this they form one segment that no single object's model explains.
  double max_depth_jump = 0.0;
  // While tracking, only the predicted proxy's image is segmented: its bounding sphere grown by
  // window_margin [m] (more than a frame's motion after the prediction).
  double window_margin = 0.03;
  // Structured-light frames (docs/tracker.md, "Structured-light frames"): a block-matching
  // sensor's depth at a pixel is the disparity of the whole correlation window around it (9 x 9
  // px on the Kinect v1; Konolige 2010, Khoshelham and Elberink 2012), so where that window
  // straddles a depth edge or a crease of the proxy the match blends the surfaces' disparities:
  // the proxy's corners come out rounded and its small faces tilted by a correlated error that no
  // per-point robust weight can tell from the surface. With window_span > 0 a proxy candidate is
  // kept only where the depths window_span px to either side (along the row and the column) exist
  // and the pixel's depth lies within window_tolerance * z^2 [m, z in m] of the line through them
  // (a plane across the window; the tolerance grows as the disparity error's depth scale, z^2).
  // 0: every candidate is kept (the statistical sensor draws its noise per pixel).
  int window_span = 0;
  double window_tolerance = 0.004;
  // A block matcher's outline: where the correlation window straddles the proxy's outline the
  // match takes whichever surface dominates it, so pixels up to half a window beyond the true
  // outline may carry the proxy's depth (a real Kinect's bleed, docs/sensor.md, "The object's
  // outline"; more with sensor.structured_light.match_in_shadow). With outline_span > 0 every
  // proxy candidate is flagged (Segmentation::outline, not dropped) when the depth outline_span px
  // to either side along its row or its column is missing or more than outline_jump * z^2 [m, z in
  // m] from its own; the tracker then judges a pose by the other points (docs/tracker.md,
  // "Judged by the interior"). 0: no flags.
  int outline_span = 2;
  double outline_jump = 0.01;

  template <class V>
  void VisitFields(V& v) {
    v("pixel_step", pixel_step);
    v("play_area_margin", play_area_margin);
    v("min_height", min_height);
    v("max_height", max_height);
    v("background", background);
    v("background_frames", background_frames);
    v("background_interval", background_interval);
    v("background_tolerance", background_tolerance);
    v("background_margin", background_margin);
    v("skin", skin);
    v("skin_cr_min", skin_cr_min);
    v("skin_cr_max", skin_cr_max);
    v("skin_cb_min", skin_cb_min);
    v("skin_cb_max", skin_cb_max);
    v("skin_grow_px", skin_grow_px);
    v("skin_grow_depth", skin_grow_depth);
    v("min_component_pixels", min_component_pixels);
    v("max_depth_jump", max_depth_jump);
    v("window_margin", window_margin);
    v("window_span", window_span);
    v("window_tolerance", window_tolerance);
    v("outline_span", outline_span);
    v("outline_jump", outline_jump);
  }
  void Validate(const std::string& prefix) const;
};

// An image rectangle [x0, x1) x [y0, y1) [px].
struct ImageRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
};

struct Segmentation {
  // Camera-frame points [m] of the proxy candidates (not skin), their component (0-based, in
  // decreasing size) and pixel index.
  std::vector<Eigen::Vector3f> points;
  std::vector<int> components;
  // Per point, 1 where it lies on the outline band (SegmentationOptions::outline_span); empty
  // when the option is off.
  std::vector<uint8_t> outline;
  // Skin-coloured foreground points [m] (the hand, or skin-coloured parts of the proxy).
  std::vector<Eigen::Vector3f> skin_points;
  // Pixel counts of the kept components, largest first.
  std::vector<int> component_sizes;
  int foreground_pixels = 0;  // in the play volume and before the background
  int skin_pixels = 0;
  int dropped_pixels = 0;  // in components under min_component_pixels
  // Proxy candidates of kept components left out by SegmentationOptions::window_span.
  int window_dropped_pixels = 0;
  ImageRect roi;           // the play volume's image
};

class Segmenter {
 public:
  // Validates the options (prefix "segmentation").
  Segmenter(const SegmentationOptions& options, const TrackSetup& setup);

  // Fixes the geometry: the table frame in the camera and the intrinsics of the depth frames.
  void SetTable(const Rigid3& camera_T_table, const PinholeIntrinsics& intrinsics);
  bool has_table() const { return has_table_; }

  // Segments `frame` (of the intrinsics given to SetTable) into `out`, only within `window` when
  // given (the predicted proxy's image: the rest of the play area is not examined).
  void Segment(const RgbdFrame& frame, Segmentation* out, const ImageRect* window = nullptr);

  // Learns the background from `frame`, leaving out `exclude` (the tracked proxy's image).
  void UpdateBackground(const RgbdFrame& frame, const ImageRect& exclude);

  const SegmentationOptions& options() const { return options_; }

 private:
  // Connected components of mask_ (mw x mh) that join neighbours only across depth steps of at
  // most max_depth_jump: per mask pixel its label (0: background), per label its pixel count.
  void DepthLimitedComponents(const RgbdFrame& frame, const ImageRect& region, int mw, int mh,
                              std::vector<int>* labels, std::vector<int>* areas) const;

  SegmentationOptions options_;
  TrackSetup setup_;
  bool has_table_ = false;
  PinholeIntrinsics intrinsics_;
  Rigid3 table_T_camera_;
  ImageRect roi_;
  // Per ROI pixel: the table-frame direction of its ray per metre of depth (#roi pixels by 3).
  std::vector<Eigen::Vector3f> table_rays_;
  // Per ROI pixel: background depth [m] (0: none yet), running mean and its count.
  std::vector<float> background_;
  std::vector<float> running_;
  std::vector<uint16_t> stable_;
  uint64_t background_calls_ = 0;
  // Scratch.
  std::vector<uint8_t> mask_;
};

}  // namespace mmh::track
