#include "montage/labelling.h"

#include <cmath>
#include <limits>

#include "core/error.h"

namespace mmh::montage {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

void LabellingOptions::Validate(const std::string& prefix) const {
  if (!std::isfinite(mu) || mu < 0) {
    ThrowBadValue(prefix + ".mu", FormatNumber(mu), "a finite number >= 0");
  }
  if (min_segment_length < 0) {
    ThrowBadValue(prefix + ".min_segment_length", std::to_string(min_segment_length),
                  "an integer >= 0 (0 switches the Segment Length Constraint off)");
  }
}

void ValidateLabellingProblem(const LabellingProblem& problem) {
  const int n = problem.frames, m = problem.takes;
  if (n < 1 || m < 1) {
    ThrowBadValue("labelling problem",
                  std::to_string(n) + " frames and " + std::to_string(m) + " takes",
                  "at least 1 frame and 1 take");
  }
  if (problem.data.size() != static_cast<std::size_t>(n) * m) {
    ThrowBadValue("labelling problem, data costs", std::to_string(problem.data.size()) + " entries",
                  std::to_string(n) + " x " + std::to_string(m));
  }
  const auto& tr = problem.transitions;
  if (tr.frames != n || tr.takes != m ||
      tr.values.size() != static_cast<std::size_t>(n - 1) * m * m) {
    ThrowBadValue("labelling problem, transition costs",
                  std::to_string(tr.values.size()) + " entries",
                  std::to_string(n - 1) + " x " + std::to_string(m) + " x " + std::to_string(m));
  }
  for (std::size_t i = 0; i < problem.data.size(); ++i) {
    if (!std::isfinite(problem.data[i])) {
      ThrowBadValue("labelling problem, data cost (frame " + std::to_string(i / m) + ", take " +
                        std::to_string(i % m) + ")",
                    FormatNumber(problem.data[i]), "a finite number");
    }
  }
  for (std::size_t i = 0; i < tr.values.size(); ++i) {
    if (!std::isfinite(tr.values[i])) {
      ThrowBadValue("labelling problem, transition cost " + std::to_string(i),
                    FormatNumber(tr.values[i]), "a finite number");
    }
  }
}

std::vector<LabelSegment> SegmentsOf(const std::vector<int>& labels) {
  std::vector<LabelSegment> segments;
  for (int t = 0; t < static_cast<int>(labels.size()); ++t) {
    if (segments.empty() || segments.back().label != labels[t]) {
      segments.push_back({labels[t], t, t});
    } else {
      segments.back().last = t;
    }
  }
  return segments;
}

LabellingResult EvaluateLabelling(const LabellingProblem& problem, const std::vector<int>& labels,
                                  double mu) {
  LabellingResult result;
  result.labels = labels;
  double smooth = 0.0;
  for (int t = 0; t < problem.frames; ++t) {
    result.data_cost += problem.data_at(t, labels[t]);
    if (t + 1 < problem.frames && labels[t] != labels[t + 1]) {
      smooth += problem.transitions.at(t, labels[t], labels[t + 1]);
    }
  }
  result.smoothness_cost = mu * smooth;
  result.total_cost = result.data_cost + result.smoothness_cost;
  return result;
}

LabellingResult SolveLabelling(const LabellingProblem& problem, const LabellingOptions& options) {
  ValidateLabellingProblem(problem);
  options.Validate("labelling");
  const int n = problem.frames, m = problem.takes, d = options.min_segment_length;
  const double mu = options.mu;

  // No labelling can satisfy the constraint: the best single take (DESIGN.md).
  if (n <= d) {
    int best = 0;
    double best_cost = kInf;
    for (int l = 0; l < m; ++l) {
      double cost = 0.0;
      for (int t = 0; t < n; ++t) cost += problem.data_at(t, l);
      if (cost < best_cost) best_cost = cost, best = l;
    }
    LabellingResult result = EvaluateLabelling(problem, std::vector<int>(n, best), mu);
    result.feasible = false;
    return result;
  }

  // prefix[(t+1) m + l] = P_l(t) = sum_{t' <= t} C_d(t', l); prefix[l] = P_l(-1) = 0.
  std::vector<double> prefix(static_cast<std::size_t>(n + 1) * m, 0.0);
  for (int t = 0; t < n; ++t) {
    for (int l = 0; l < m; ++l) {
      prefix[static_cast<std::size_t>(t + 1) * m + l] =
          prefix[static_cast<std::size_t>(t) * m + l] + problem.data_at(t, l);
    }
  }
  auto P = [&](int t, int l) { return prefix[static_cast<std::size_t>(t + 1) * m + l]; };

  // V(e, l): best cost of frames [0, e] whose last segment has take l and ends at e.
  std::vector<double> value(static_cast<std::size_t>(n) * m, kInf);
  // G(s, l) and its best previous take; running minimum of G over s <= e - d and its argmin.
  std::vector<int> previous(static_cast<std::size_t>(n) * m, -1);
  std::vector<int> start(static_cast<std::size_t>(n) * m, 0);
  std::vector<double> running(m, kInf);
  std::vector<int> running_start(m, 0);

  for (int e = 0; e < n; ++e) {
    // Admit the segment start s = e - d: G(s, l) needs V(s - 1, .), known since s - 1 < e.
    const int s = e - d;
    if (s >= 0) {
      for (int l = 0; l < m; ++l) {
        double g;
        int best_k = -1;
        if (s == 0) {
          g = 0.0;  // the first segment: no transition before it
        } else {
          g = kInf;
          for (int k = 0; k < m; ++k) {
            if (k == l) continue;
            const double v = value[static_cast<std::size_t>(s - 1) * m + k] +
                             mu * problem.transitions.at(s - 1, k, l);
            if (v < g) g = v, best_k = k;
          }
          g -= P(s - 1, l);
        }
        previous[static_cast<std::size_t>(s) * m + l] = best_k;
        if (g < running[l]) running[l] = g, running_start[l] = s;
      }
    }
    for (int l = 0; l < m; ++l) {
      if (running[l] < kInf) {
        value[static_cast<std::size_t>(e) * m + l] = P(e, l) + running[l];
        start[static_cast<std::size_t>(e) * m + l] = running_start[l];
      }
    }
  }

  int label = 0;
  for (int l = 1; l < m; ++l) {
    if (value[static_cast<std::size_t>(n - 1) * m + l] <
        value[static_cast<std::size_t>(n - 1) * m + label]) {
      label = l;
    }
  }
  std::vector<int> labels(n, 0);
  int e = n - 1;
  while (true) {
    const int s = start[static_cast<std::size_t>(e) * m + label];
    for (int t = s; t <= e; ++t) labels[t] = label;
    if (s == 0) break;
    label = previous[static_cast<std::size_t>(s) * m + label];
    e = s - 1;
  }
  // Report the cost of the labelling summed frame by frame (not the prefix-sum differences).
  return EvaluateLabelling(problem, labels, mu);
}

}  // namespace mmh::montage
