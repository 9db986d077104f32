#include "metrics/tracking_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <tuple>

#include "core/error.h"

namespace mmh::metrics {

void PoseErrorOptions::Validate(const std::string& prefix) const {
  RequirePositive(success_rotation_deg, prefix + ".success_rotation_deg", "deg");
  RequirePositive(success_translation, prefix + ".success_translation", "m");
  RequirePositive(add_fraction, prefix + ".add_fraction");
}

Eigen::Matrix<double, Eigen::Dynamic, 3> MetricPoints(const TriangleMesh& mesh, int max_points) {
  std::set<std::tuple<float, float, float>> seen;
  std::vector<Eigen::Vector3d> unique;
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const auto key = std::make_tuple(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2));
    if (seen.insert(key).second) unique.push_back(mesh.vertices.row(i).cast<double>().transpose());
  }
  const size_t count = std::min(unique.size(), static_cast<size_t>(std::max(max_points, 1)));
  Eigen::Matrix<double, Eigen::Dynamic, 3> points(count, 3);
  for (size_t i = 0; i < count; ++i) points.row(i) = unique[i * unique.size() / count].transpose();
  return points;
}

double Diameter(const Eigen::Matrix<double, Eigen::Dynamic, 3>& points) {
  double best = 0.0;
  for (int i = 0; i < points.rows(); ++i) {
    for (int j = i + 1; j < points.rows(); ++j) {
      best = std::max(best, (points.row(i) - points.row(j)).squaredNorm());
    }
  }
  return std::sqrt(best);
}

std::vector<FramePoseError> ComputePoseErrors(
    const std::vector<std::optional<Rigid3>>& estimates, const std::vector<Rigid3>& truth,
    const Eigen::Matrix<double, Eigen::Dynamic, 3>& points, const PoseErrorOptions& options) {
  options.Validate("metrics");
  if (estimates.size() != truth.size()) {
    ThrowBadValue("pose errors", std::to_string(estimates.size()) + " estimates",
                  std::to_string(truth.size()) + " (one per ground-truth frame)");
  }
  std::vector<FramePoseError> errors(truth.size());
  const int n = static_cast<int>(points.rows());
  // ADD-S's nearest neighbours are searched in the estimate's model frame, where the estimated
  // points are the model's own (distances do not change under a rigid transform): the model
  // points sorted by x once, then for each query a sweep outwards from its x that stops when the
  // x gap alone exceeds the best distance found. Exact, and about n^(2/3) distances per query
  // instead of n.
  std::vector<Eigen::Vector3d> sorted(n);
  for (int i = 0; i < n; ++i) sorted[i] = points.row(i).transpose();
  std::sort(sorted.begin(), sorted.end(),
            [](const Eigen::Vector3d& u, const Eigen::Vector3d& v) { return u.x() < v.x(); });
  auto nearest_squared = [&](const Eigen::Vector3d& q) {
    const auto start =
        std::lower_bound(sorted.begin(), sorted.end(), q.x(),
                         [](const Eigen::Vector3d& u, double x) { return u.x() < x; });
    double best = std::numeric_limits<double>::infinity();
    for (auto it = start; it != sorted.end(); ++it) {
      const double dx = it->x() - q.x();
      if (dx * dx >= best) break;
      best = std::min(best, (*it - q).squaredNorm());
    }
    for (auto it = start; it != sorted.begin();) {
      --it;
      const double dx = q.x() - it->x();
      if (dx * dx >= best) break;
      best = std::min(best, (*it - q).squaredNorm());
    }
    return best;
  };
  for (size_t f = 0; f < truth.size(); ++f) {
    FramePoseError& e = errors[f];
    if (!estimates[f]) continue;
    const Rigid3& est = *estimates[f];
    e.has_estimate = true;
    e.rotation_deg = RotationAngle(est.rotation, truth[f].rotation) * 180 / std::numbers::pi;
    e.translation = (est.translation - truth[f].translation).norm();
    // estimate⁻¹ · truth: a true point in the estimate's model frame.
    const Rigid3 estimate_T_truth = est.Inverse() * truth[f];
    double add = 0.0, adds = 0.0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = points.row(i).transpose();
      const Eigen::Vector3d q = estimate_T_truth * p;
      add += (q - p).norm();
      // ADD-S: each true point to its nearest estimated point.
      adds += std::sqrt(nearest_squared(q));
    }
    e.add = n > 0 ? add / n : 0.0;
    e.adds = n > 0 ? adds / n : 0.0;
    e.success = e.rotation_deg <= options.success_rotation_deg &&
                e.translation <= options.success_translation;
  }
  return errors;
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double h = (values.size() - 1) * q;
  const size_t lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (h - lo) * (values[hi] - values[lo]);
}

TrackingSummary SummarizeTracking(const std::vector<FramePoseError>& errors, double diameter,
                                  const PoseErrorOptions& options) {
  options.Validate("metrics");
  TrackingSummary s;
  s.frames = static_cast<int>(errors.size());
  s.diameter = diameter;
  std::vector<double> rotations, translations;
  int successes = 0, add_ok = 0, adds_ok = 0;
  double add_sum = 0.0, adds_sum = 0.0;
  const double add_limit = options.add_fraction * diameter;
  for (size_t f = 0; f < errors.size(); ++f) {
    const FramePoseError& e = errors[f];
    if (e.has_estimate) {
      ++s.frames_with_estimate;
      rotations.push_back(e.rotation_deg);
      translations.push_back(e.translation);
      add_sum += e.add;
      adds_sum += e.adds;
      add_ok += e.add < add_limit;
      adds_ok += e.adds < add_limit;
    }
    successes += e.success;
    if (!e.success) {
      if (s.failures.empty() ||
          s.failures.back().first + s.failures.back().length != static_cast<int>(f)) {
        s.failures.push_back({static_cast<int>(f), 0, false});
      }
      ++s.failures.back().length;
    } else if (!s.failures.empty() &&
               s.failures.back().first + s.failures.back().length == static_cast<int>(f)) {
      s.failures.back().recovered = true;
    }
  }
  s.median_rotation_deg = Quantile(rotations, 0.5);
  s.median_translation = Quantile(translations, 0.5);
  s.p95_rotation_deg = Quantile(rotations, 0.95);
  s.p95_translation = Quantile(translations, 0.95);
  if (s.frames_with_estimate > 0) {
    s.mean_add = add_sum / s.frames_with_estimate;
    s.mean_adds = adds_sum / s.frames_with_estimate;
  }
  if (s.frames > 0) {
    s.success_rate = static_cast<double>(successes) / s.frames;
    s.add_success_rate = static_cast<double>(add_ok) / s.frames;
    s.adds_success_rate = static_cast<double>(adds_ok) / s.frames;
  }
  for (const FailureRun& run : s.failures) {
    s.longest_failure = std::max(s.longest_failure, run.length);
    s.all_recovered = s.all_recovered && run.recovered;
  }
  return s;
}

nlohmann::json ToJson(const TrackingSummary& s) {
  nlohmann::json failures = nlohmann::json::array();
  for (const FailureRun& run : s.failures) {
    failures.push_back(
        {{"first", run.first}, {"length", run.length}, {"recovered", run.recovered}});
  }
  return {{"frames", s.frames},
          {"frames_with_estimate", s.frames_with_estimate},
          {"median_rotation_deg", s.median_rotation_deg},
          {"median_translation_m", s.median_translation},
          {"p95_rotation_deg", s.p95_rotation_deg},
          {"p95_translation_m", s.p95_translation},
          {"mean_add_m", s.mean_add},
          {"mean_adds_m", s.mean_adds},
          {"success_rate", s.success_rate},
          {"add_success_rate", s.add_success_rate},
          {"adds_success_rate", s.adds_success_rate},
          {"diameter_m", s.diameter},
          {"failures", failures},
          {"longest_failure_frames", s.longest_failure},
          {"all_recovered", s.all_recovered}};
}

}  // namespace mmh::metrics
