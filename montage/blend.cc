#include "montage/blend.h"

#include <algorithm>

#include "core/error.h"
#include "montage/labelling.h"

namespace mmh::montage {
namespace {

constexpr std::pair<BlendWeight, const char*> kWeightNames[] = {
    {BlendWeight::kLinear, "linear"},
    {BlendWeight::kSmoothstep, "smoothstep"},
};

}  // namespace

std::span<const std::pair<BlendWeight, const char*>> EnumNames(BlendWeight) { return kWeightNames; }

void BlendOptions::Validate(const std::string& prefix) const {
  if (window < 1 || window % 2 == 0 || window > 1001) {
    ThrowBadValue(prefix + ".window", std::to_string(window),
                  "an odd number of frames in [1, 1001] (1: no blending)");
  }
}

std::vector<MontageSegment> Unwarp(const std::vector<int>& labels,
                                   const std::vector<std::vector<int>>& warps) {
  std::vector<MontageSegment> segments;
  int montage_frame = 0;
  for (const LabelSegment& s : SegmentsOf(labels)) {
    MontageSegment segment;
    segment.take = s.label;
    segment.reference_first = s.first;
    segment.reference_last = s.last;
    segment.source_first = warps[s.label][s.first];
    segment.source_last = warps[s.label][s.last];
    segment.montage_first = montage_frame;
    segment.montage_last = montage_frame + segment.source_last - segment.source_first;
    montage_frame = segment.montage_last + 1;
    segments.push_back(segment);
  }
  return segments;
}

Trajectory BlendMontage(const std::vector<Trajectory>& takes,
                        const std::vector<MontageSegment>& segments, const BlendOptions& options,
                        double start_time, double frame_period, int* narrowed) {
  Trajectory montage;
  const int frames = segments.empty() ? 0 : segments.back().montage_last + 1;
  montage.poses.reserve(frames);
  montage.timestamps.reserve(frames);
  for (const auto& s : segments) {
    const Trajectory& take = takes[s.take];
    for (int i = s.source_first; i <= s.source_last; ++i) montage.poses.push_back(take.poses[i]);
  }
  for (int f = 0; f < frames; ++f) montage.timestamps.push_back(start_time + f * frame_period);
  if (narrowed) *narrowed = 0;

  const int half = (options.window - 1) / 2;
  auto length = [](const MontageSegment& s) { return s.montage_last - s.montage_first + 1; };
  for (std::size_t j = 1; j < segments.size(); ++j) {
    const MontageSegment& out = segments[j - 1];
    const MontageSegment& in = segments[j];
    // Keep neighbouring windows apart: each side of a segment uses at most (length - 1) / 2.
    const int h = std::min({half, (length(out) - 1) / 2, (length(in) - 1) / 2});
    if (h < half && narrowed) ++*narrowed;
    if (h <= 0) continue;
    const Trajectory& a = takes[out.take];
    const Trajectory& b = takes[in.take];
    const int i = in.montage_first;  // first frame of the incoming segment
    for (int f = i - h; f <= i + h; ++f) {
      // The outgoing take continued past its segment, the incoming one before its segment.
      const int sa = std::clamp(out.source_last + (f - (i - 1)), 0, static_cast<int>(a.size()) - 1);
      const int sb = std::clamp(in.source_first + (f - i), 0, static_cast<int>(b.size()) - 1);
      double w = static_cast<double>(f - i + h + 1) / (2 * h + 2);
      if (options.weight == BlendWeight::kSmoothstep) w = w * w * (3 - 2 * w);
      montage.poses[f] = Interpolate(a.poses[sa], b.poses[sb], w);
    }
  }
  return montage;
}

}  // namespace mmh::montage
