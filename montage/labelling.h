// The labelling of the warped montage (paper eqs. 7-12): choose a take l_t for every reference
// frame t to minimise
//   C_T = sum_t C_d(t, l_t) + mu sum_{t<n-1} C_s(t, l_t, l_{t+1})                (eq. 7)
// subject to the Segment Length Constraint: every maximal run of one label (segment), the first
// and the last included, is longer than d frames (eq. 12).
//
// Solved exactly by a semi-Markov dynamic programme in O(n m^2) time and O(n m) memory: with prefix
// sums P_l of the data cost, the best cost of frames [0, e] ending in a segment of take l that
// starts at s is P_l(e) + min_{s <= e-d} G(s, l), G(s, l) = min_{k != l} (V(s-1, k) +
// mu C_s(s-1, k, l)) - P_l(s-1), and the minimum over s is a running minimum as e grows. d = 0 is
// the Markov-chain Max-Sum of eq. 10.
#pragma once

#include <string>
#include <vector>

#include "montage/smoothness.h"

namespace mmh::montage {

struct LabellingOptions {
  // mu of eq. 7: weight of the smoothness cost against the data cost. Paper: 100.
  double mu = 100.0;
  // d of eq. 12 [frames]: every segment must be longer than d (d = 60: at least 61 frames).
  // 0 switches the constraint off (eq. 10). Paper: 60.
  int min_segment_length = 60;

  template <class V>
  void VisitFields(V& v) {
    v("mu", mu);
    v("min_segment_length", min_segment_length);
  }
  void Validate(const std::string& prefix) const;
};

// Costs of one labelling problem.
struct LabellingProblem {
  int frames = 0;  // n
  int takes = 0;   // m
  // C_d(t, l) = data[t * m + l]; #n by m. The compositor sets it to -a'_l(t) (eq. 8).
  std::vector<double> data;
  // C_s(t, l, k) for t < n - 1 (not yet multiplied by mu).
  TransitionCosts transitions;

  double data_at(int t, int l) const { return data[static_cast<std::size_t>(t) * takes + l]; }
};

struct LabelSegment {
  int label = 0;
  int first = 0;  // first frame, inclusive
  int last = 0;   // last frame, inclusive
  int length() const { return last - first + 1; }
};

struct LabellingResult {
  // n labels in [0, m).
  std::vector<int> labels;
  // C_T of eq. 7 and its two terms (the smoothness term already multiplied by mu).
  double total_cost = 0.0;
  double data_cost = 0.0;
  double smoothness_cost = 0.0;
  // False if no labelling satisfies the constraint (n <= d); the result is then the single take of
  // least cost.
  bool feasible = true;
};

// Checks sizes and finiteness (InputError naming the offending entry).
void ValidateLabellingProblem(const LabellingProblem& problem);

// The exact optimum. Ties are broken deterministically.
LabellingResult SolveLabelling(const LabellingProblem& problem, const LabellingOptions& options);

// C_T of eq. 7 for any labelling, and its terms (for tests and reports).
LabellingResult EvaluateLabelling(const LabellingProblem& problem, const std::vector<int>& labels,
                                  double mu);

// Maximal runs of one label.
std::vector<LabelSegment> SegmentsOf(const std::vector<int>& labels);

}  // namespace mmh::montage
