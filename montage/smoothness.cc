#include "montage/smoothness.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "montage/internal/pose_arrays.h"
#include "montage/match_cost.h"

namespace mmh::montage {
namespace {

constexpr std::pair<WindowEdge, const char*> kEdgeNames[] = {
    {WindowEdge::kScaledMean, "scaled_mean"},
    {WindowEdge::kTruncatedSum, "truncated_sum"},
};

using internal::PoseArrays;

// Eq. 9's sum over the `valid` pairs of a window, with the edge rule of WindowEdge. The one place
// that scales, so that the table and the direct evaluation round alike.
double WindowSum(double sum, int valid, const SmoothnessOptions& options) {
  const int full = 2 * options.half_window + 1;
  if (options.window_edge == WindowEdge::kScaledMean && valid < full) sum = sum / valid * full;
  return sum;
}

// out[i] = C_match(l[a + i], k[b + i]) for i < count: one diagonal of eq. 9's window. Inlined into
// each SIMD clone of its caller (one dispatch per take pair, not per window).
[[gnu::always_inline]] inline void DiagonalCosts(const PoseArrays& l, int a, const PoseArrays& k,
                                                 int b, int count, double lambda,
                                                 double* __restrict out) {
  const double* __restrict ax = l.qx.data() + a;
  const double* __restrict ay = l.qy.data() + a;
  const double* __restrict az = l.qz.data() + a;
  const double* __restrict aw = l.qw.data() + a;
  const double* __restrict atx = l.tx.data() + a;
  const double* __restrict aty = l.ty.data() + a;
  const double* __restrict atz = l.tz.data() + a;
  const double* __restrict bx = k.qx.data() + b;
  const double* __restrict by = k.qy.data() + b;
  const double* __restrict bz = k.qz.data() + b;
  const double* __restrict bw = k.qw.data() + b;
  const double* __restrict btx = k.tx.data() + b;
  const double* __restrict bty = k.ty.data() + b;
  const double* __restrict btz = k.tz.data() + b;
  for (int i = 0; i < count; ++i) {
    out[i] = MatchCost(ax[i], ay[i], az[i], aw[i], atx[i], aty[i], atz[i], bx[i], by[i], bz[i],
                       bw[i], btx[i], bty[i], btz[i], lambda);
  }
}

// Eq. 9 around centres cl (take l) and ck (take k, already w_k(t+1) - 1), over the valid part of
// the window, summed in h order.
MMH_SIMD_CLONES
double WindowCost(const PoseArrays& l, int cl, const PoseArrays& k, int ck,
                  const SmoothnessOptions& options, double* scratch) {
  const int h = options.half_window;
  // Valid h: 0 <= cl + h < l.size() and 0 <= ck + h < k.size().
  const int lo = std::max({-h, -cl, -ck});
  const int hi = std::min({h, l.size() - 1 - cl, k.size() - 1 - ck});
  const int valid = hi - lo + 1;
  if (valid <= 0) return 0.0;
  DiagonalCosts(l, cl + lo, k, ck + lo, valid, options.lambda, scratch);
  double sum = 0.0;
  for (int i = 0; i < valid; ++i) sum += scratch[i];
  return WindowSum(sum, valid, options);
}

}  // namespace

std::span<const std::pair<WindowEdge, const char*>> EnumNames(WindowEdge) { return kEdgeNames; }

void SmoothnessOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(lambda) || lambda < 0) {
    ThrowBadValue(prefix + ".lambda", FormatNumber(lambda), "a finite number >= 0");
  }
  if (half_window < 0 || half_window > 1000) {
    ThrowBadValue(prefix + ".half_window", std::to_string(half_window), "an integer in [0, 1000]");
  }
}

namespace {

// All entries C_s(., l, k) of one ordered pair of takes. Eq. 9 sums C_match along a diagonal of the
// (source l, source k) plane around the centre (w_l(t), w_k(t+1) - 1). Consecutive frames whose
// centres lie on the same diagonal share most of their window, so each C_match of such a run is
// computed once, and every window is then summed from those values in h order, exactly as
// WindowCost sums it: the table equals the direct evaluation to the last bit.
MMH_SIMD_CLONES
void FillPair(const PoseArrays& take_l, const std::vector<int>& warp_l, const PoseArrays& take_k,
              const std::vector<int>& warp_k, int l, int k, const SmoothnessOptions& options,
              TransitionCosts* table, std::vector<double>* scratch) {
  const int n = static_cast<int>(warp_l.size());
  const int h = options.half_window;
  const int m = table->takes;
  int t = 0;
  while (t < n - 1) {
    // The run [t, end) of frames on one diagonal a - b = offset, centres not going back and not
    // jumping past a window.
    const int offset = warp_l[t] - (warp_k[t + 1] - 1);
    int end = t + 1;
    while (end < n - 1 && warp_l[end] - (warp_k[end + 1] - 1) == offset &&
           warp_l[end] >= warp_l[end - 1] && warp_l[end] - warp_l[end - 1] <= 2 * h + 1) {
      ++end;
    }
    // Source frames a of take l (b = a - offset of take k) that any window of the run uses.
    const int lo = std::max({warp_l[t] - h, 0, offset});
    const int hi = std::min({warp_l[end - 1] + h, take_l.size() - 1, take_k.size() - 1 + offset});
    if (hi >= lo) {
      scratch->resize(hi - lo + 1);
      DiagonalCosts(take_l, lo, take_k, lo - offset, hi - lo + 1, options.lambda, scratch->data());
    }
    for (int u = t; u < end; ++u) {
      const int c = warp_l[u];
      const int first = std::max({c - h, 0, offset});
      const int last = std::min({c + h, take_l.size() - 1, take_k.size() - 1 + offset});
      const int valid = last - first + 1;
      double sum = 0.0;
      if (valid > 0) {
        for (int a = first; a <= last; ++a) sum += (*scratch)[a - lo];
        sum = WindowSum(sum, valid, options);
      }
      table->values[(static_cast<std::size_t>(u) * m + l) * m + k] = sum;
    }
    t = end;
  }
}

}  // namespace

TransitionCosts ComputeSmoothnessCosts(const std::vector<Trajectory>& takes,
                                       const std::vector<std::vector<int>>& warps,
                                       const SmoothnessOptions& options) {
  const int m = static_cast<int>(takes.size());
  const int n = warps.empty() ? 0 : static_cast<int>(warps[0].size());
  TransitionCosts table;
  table.frames = n;
  table.takes = m;
  table.values.assign(static_cast<std::size_t>(std::max(0, n - 1)) * m * m, 0.0);
  std::vector<PoseArrays> columns;
  columns.reserve(m);
  for (const auto& take : takes) columns.emplace_back(take);
  // One task per ordered pair; each writes only its own entries, so the table is the same for any
  // thread count.
  tbb::parallel_for(0, m * m, [&](int pair) {
    const int l = pair / m, k = pair % m;
    if (l == k) return;
    std::vector<double> scratch;
    FillPair(columns[l], warps[l], columns[k], warps[k], l, k, options, &table, &scratch);
  });
  return table;
}

double SmoothnessCost(const Trajectory& take_l, const std::vector<int>& warp_l,
                      const Trajectory& take_k, const std::vector<int>& warp_k, int t,
                      const SmoothnessOptions& options) {
  if (&take_l == &take_k) return 0.0;
  const PoseArrays l(take_l), k(take_k);
  std::vector<double> scratch(2 * options.half_window + 1);
  return WindowCost(l, warp_l[t], k, warp_k[t + 1] - 1, options, scratch.data());
}

}  // namespace mmh::montage
