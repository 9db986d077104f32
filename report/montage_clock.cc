#include "report/montage_clock.h"

#include <string>

#include "core/error.h"

namespace mmh::report {

MontageClock ComputeMontageClock(const std::vector<montage::MontageSegment>& segments,
                                 const std::vector<std::vector<int>>& warps) {
  MontageClock clock;
  clock.takes.resize(warps.size());
  const int n = warps.empty() ? 0 : static_cast<int>(warps.front().size());
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const montage::MontageSegment& s = segments[i];
    const std::string where = "segment " + std::to_string(i);
    if (s.take < 0 || s.take >= static_cast<int>(warps.size())) {
      ThrowBadValue(where + " take", std::to_string(s.take), "a take of the montage");
    }
    if (s.montage_first != static_cast<int>(clock.reference.size()) ||
        s.montage_last - s.montage_first != s.source_last - s.source_first ||
        s.reference_first < 0 || s.reference_last < s.reference_first || s.reference_last >= n) {
      ThrowBadValue(where, "montage frames " + std::to_string(s.montage_first) + ".." +
                               std::to_string(s.montage_last) + ", reference frames " +
                               std::to_string(s.reference_first) + ".." +
                               std::to_string(s.reference_last),
                    "segments that tile the montage from frame 0, each as long as its source "
                    "frames, on the reference timeline");
    }
    const std::vector<int>& warp = warps[s.take];
    int t = s.reference_first;
    for (int j = s.source_first; j <= s.source_last; ++j) {
      while (t < s.reference_last && warp[t] < j) ++t;
      clock.reference.push_back(t);
      for (std::size_t k = 0; k < warps.size(); ++k) {
        clock.takes[k].push_back(static_cast<int>(k) == s.take ? j : warps[k][t]);
      }
    }
  }
  return clock;
}

}  // namespace mmh::report
