// Dynamic time warping of a source take to the reference take (paper eqs. 1-5).
//
// The warp w maps every reference frame t in [0, n) to a source frame w(t) in [0, N) (0-based
// here; the paper counts from 1). It is monotone (t1 > t2 => w(t1) >= w(t2), eq. 2) and fixes both
// ends (w(0) = 0, w(n-1) = N-1, eq. 3). The default step pattern is eq. 4 read literally: each
// reference frame gets one source frame and the cost is
//   sum_t C_match(T_ref(t), T_src(w(t)))                                       (eq. 4)
// with C_match of eq. 5 (match_cost.h). The warp may stay on a source frame (flat) or skip any
// number of source frames between two reference frames.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/trajectory.h"

namespace mmh::montage {

enum class StepPattern {
  // Eq. 4 literally: w(t+1) - w(t) >= 0, any size. The default.
  kLiteral,
  // Like kLiteral but w(t+1) - w(t) in {0, 1, 2} (slope at most 2, Itakura-like); needs
  // N - 1 <= 2 (n - 1).
  kSlopeLimited,
  // The classic symmetric DTW of Myers & Rabiner: a path of cells with steps (1,0), (0,1), (1,1),
  // cost summed over every cell of the path; w(t) is the first source frame the path matches to t
  // for t < n-1, and w(n-1) = N-1.
  kSymmetric,
};
std::span<const std::pair<StepPattern, const char*>> EnumNames(StepPattern);

struct DtwOptions {
  // lambda of eq. 5 [1/m]: weight of the translation distance against the quaternion distance.
  // Paper: 2.5 "based on experimentation".
  double lambda = 2.5;
  // Which monotone warps are allowed; see StepPattern. Paper: eq. 4 (kLiteral).
  StepPattern step_pattern = StepPattern::kLiteral;
  // kLiteral only: skip cells that provably cannot lie on an optimal warp (lower bounds from
  // bounding balls of source blocks, forward and backward). The result is identical to the full
  // dynamic programme (same warp, same cost); false forces the full O(n N) programme.
  bool prune = true;

  template <class V>
  void VisitFields(V& v) {
    v("lambda", lambda);
    v("step_pattern", step_pattern);
    v("prune", prune);
  }
  void Validate(const std::string& prefix) const;
};

struct DtwSummary {
  // Cost of the returned warp (eq. 4 sum, or the path sum for kSymmetric).
  double cost = 0.0;
  // C_match evaluations over all passes (the pruned programme runs a coarse pass, a band pass and
  // the exact pass, so on unrelated takes, where nothing can be pruned, this can exceed n * N),
  // and n * N, the full programme's count.
  std::int64_t cells_evaluated = 0;
  std::int64_t cells_total = 0;
  // Wall time in seconds.
  double seconds = 0.0;
};

struct DtwResult {
  // n entries: the source frame of each reference frame (0-based), monotone, w(0) = 0,
  // w(n-1) = N-1.
  std::vector<int> warp;
  DtwSummary summary;
};

// Optimal warp of `source` onto `reference`. Throws InputError if no warp of the pattern exists
// (n = 1 < N, or N - 1 > 2 (n - 1) for kSlopeLimited) or either take is empty.
DtwResult ComputeDtw(const Trajectory& reference, const Trajectory& source,
                     const DtwOptions& options);

// The eq. 4 cost of a warp: sum_t C_match(T_ref(t), T_src(warp[t])). Does not check validity.
double WarpCost(const Trajectory& reference, const Trajectory& source, const std::vector<int>& warp,
                double lambda);

// True if `warp` is valid for the pattern: n entries, monotone, both ends fixed, steps allowed.
bool IsValidWarp(const std::vector<int>& warp, int source_frames, StepPattern pattern);

}  // namespace mmh::montage
