// The smoothness cost of eq. 9 between every pair of takes at every reference frame:
//   C_s(t, l, k) = sum_{h in W} C_match(T_l(w_l(t) + h), T_k(w_k(t+1) + h - 1)),  W = [-7, 7],
// on the unwarped takes, with lambda = 0.8; C_s(t, l, l) = 0 (staying in a take costs nothing).
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/trajectory.h"

namespace mmh::montage {

enum class WindowEdge {
  // Near a take's ends some of the 15 pairs fall outside a take. The mean over the valid pairs,
  // scaled to the full window (x 15 / valid), so that the cost does not fall near the ends and
  // draw transitions there (default; DESIGN.md).
  kScaledMean,
  // The paper's "suitably truncated" sum over the valid pairs only.
  kTruncatedSum,
};
std::span<const std::pair<WindowEdge, const char*>> EnumNames(WindowEdge);

struct SmoothnessOptions {
  // lambda of eq. 5 inside eq. 9 [1/m]. Paper: 0.8.
  double lambda = 0.8;
  // W = [-half_window, half_window] frames. Paper: 7.
  int half_window = 7;
  // Treatment of the window near the ends of a take; see WindowEdge.
  WindowEdge window_edge = WindowEdge::kScaledMean;

  template <class V>
  void VisitFields(V& v) {
    v("lambda", lambda);
    v("half_window", half_window);
    v("window_edge", window_edge);
  }
  void Validate(const std::string& prefix) const;
};

// C_s for t in [0, n-1) and every ordered pair (l, k): #(n-1) by m by m, stored t-major:
// at(t, l, k) = values[(t * m + l) * m + k]. Diagonal entries are 0.
struct TransitionCosts {
  int frames = 0;  // n; the table has n - 1 rows
  int takes = 0;   // m
  std::vector<double> values;

  double at(int t, int l, int k) const {
    return values[(static_cast<std::size_t>(t) * takes + l) * takes + k];
  }
};

// `takes` are the unwarped takes, `warps[l]` the warp of take l onto the reference (n entries each;
// the reference's own warp is the identity).
TransitionCosts ComputeSmoothnessCosts(const std::vector<Trajectory>& takes,
                                       const std::vector<std::vector<int>>& warps,
                                       const SmoothnessOptions& options);

// One entry of the table, computed directly (the oracle for the table).
double SmoothnessCost(const Trajectory& take_l, const std::vector<int>& warp_l,
                      const Trajectory& take_k, const std::vector<int>& warp_k, int t,
                      const SmoothnessOptions& options);

}  // namespace mmh::montage
