// How far an object's depth reaches past its silhouette, and how much of the silhouette is lost,
// on each side of the object along the image rows: the depth image against the object's mask
// (the label of a real frame, the exact silhouette of a rendered one). A block matcher's window
// that straddles the object's edge may take the near surface's disparity (the object "bleeds" or
// "fattens" onto the background) or the far one's, or fail (the silhouette erodes). A tracker that
// fits a model to the object's points sees bled pixels as points off the model, so this is the
// sensor statistic it feels at the object's outline.
//
// Per row, each run of mask pixels at least min_run_px long has two ends. At an end:
//  - z_object is the median of the valid depths of the run's first reference_px pixels from that
//    end (at least 3 valid, else the end is skipped);
//  - z_background is the median of the valid depths outside the mask at background_from_px ..
//    background_to_px pixels beyond the end (at least 3 valid, else skipped); the end counts only
//    where z_background >= z_object + min_step_m (the object in front of its background);
//  - bleed: the number of consecutive pixels beyond the end, outside the mask, that are valid and
//    within depth_tolerance_m of z_object (at most max_px);
//  - erosion: the number of consecutive mask pixels from the end inwards that are missing or
//    farther than z_object + depth_tolerance_m (at most max_px).
// The shadow side is the left end of a run (u decreasing: the projector sits along +x, so its
// shadow falls left of near edges, as ClassifyMissing's shadow runs), the edge side the right end
// (the IR camera's occlusion). Lengths in this frame's pixels.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace mmh::sim {

struct SilhouetteBleedOptions {
  double depth_tolerance_m =
      0.01;                  // a pixel "at the object's depth" (several lattice steps at 1 m)
  double min_step_m = 0.03;  // the background at least this much farther
  int min_run_px = 8;        // shorter runs of the mask (thin parts) are left out
  int reference_px = 6;      // pixels from the end that give z_object
  int background_from_px = 17, background_to_px = 25;  // beyond max_px: past any bleed
  int max_px = 15;

  void Validate(const std::string& prefix) const;
};

struct SideBleed {
  int ends = 0;                                                  // run ends measured
  double bleed_px = std::numeric_limits<double>::quiet_NaN();    // mean over the ends (NaN: none)
  double erosion_px = std::numeric_limits<double>::quiet_NaN();  // mean over the ends
  double bled_share = std::numeric_limits<double>::quiet_NaN();  // of the ends with a bleed > 0
};

struct SilhouetteBleed {
  SideBleed shadow_side;  // the run's left end
  SideBleed edge_side;    // its right end
};

// `depth_m`: width x height row-major [m], 0 or NaN = missing; `mask`: the object's pixels
// (non-zero); `excluded` (empty or width x height, non-zero = left out): an end whose bleed,
// erosion or background pixels touch it is not measured (other objects' neighbourhoods).
SilhouetteBleed MeasureSilhouetteBleed(const std::vector<float>& depth_m, int width, int height,
                                       std::span<const uint8_t> mask,
                                       const SilhouetteBleedOptions& options = {},
                                       std::span<const uint8_t> excluded = {});

}  // namespace mmh::sim
