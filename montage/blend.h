// Unwarping the labelled montage to the takes' original speeds, and blending across transitions
// (paper, "Unwarping the Montage" and "Motion Blending").
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/trajectory.h"

namespace mmh::montage {

enum class BlendWeight {
  // w = (f - i + (W+1)/2) / (W+1) across the window: linear, as in the paper.
  kLinear,
  // The same ramp through 3w^2 - 2w^3 (C1 at the window's ends).
  kSmoothstep,
};
std::span<const std::pair<BlendWeight, const char*>> EnumNames(BlendWeight);

struct BlendOptions {
  // Frames in the blending window centred on each transition (odd). Paper: 15. 1 = no blending.
  int window = 15;
  // Weight profile; see BlendWeight. Paper: linear.
  BlendWeight weight = BlendWeight::kLinear;

  template <class V>
  void VisitFields(V& v) {
    v("window", window);
    v("weight", weight);
  }
  void Validate(const std::string& prefix) const;
};

// One segment of the montage: reference frames [reference_first, reference_last] taken from take
// `take`, played at that take's own speed as its source frames [source_first, source_last], which
// become montage frames [montage_first, montage_last]. All ranges inclusive, 0-based.
struct MontageSegment {
  int take = 0;
  int reference_first = 0;
  int reference_last = 0;
  int source_first = 0;
  int source_last = 0;
  int montage_first = 0;
  int montage_last = 0;
};

// Replaces each warped segment by the interval [w_l(first), w_l(last)] of its original take and
// concatenates them. `labels` has n entries, `warps[l]` n entries each.
std::vector<MontageSegment> Unwarp(const std::vector<int>& labels,
                                   const std::vector<std::vector<int>>& warps);

// The montage's poses: the segments' source poses, blended over a window centred on each
// transition (lerp of translations, slerp of rotations). Around the transition into montage frame
// i, frame f in [i - W/2, i + W/2] gets Interpolate(outgoing take continued past its segment,
// incoming take before its segment, weight(f)); the continuations clamp at the takes' ends. The
// half-window shrinks where a segment is shorter than the window (reported in `narrowed`).
// Timestamps start at `start_time` with `frame_period` spacing.
Trajectory BlendMontage(const std::vector<Trajectory>& takes,
                        const std::vector<MontageSegment>& segments, const BlendOptions& options,
                        double start_time, double frame_period, int* narrowed = nullptr);

}  // namespace mmh::montage
