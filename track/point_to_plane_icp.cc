#include "track/point_to_plane_icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>

#include "core/error.h"
#include "track/internal/pose_update.h"

namespace mmh::track {

void IcpOptions::Validate(const std::string& prefix) const {
  if (max_iterations < 1 || max_iterations > 1000) {
    ThrowBadValue(prefix + ".max_iterations", std::to_string(max_iterations),
                  "an integer in [1, 1000]");
  }
  RequirePositive(start_distance, prefix + ".start_distance", "m");
  RequirePositive(end_distance, prefix + ".end_distance", "m");
  if (end_distance > start_distance) {
    ThrowBadValue(prefix + ".end_distance", FormatNumber(end_distance),
                  "at most start_distance = " + FormatNumber(start_distance) + " m");
  }
  if (shrink_iterations < 0) {
    ThrowBadValue(prefix + ".shrink_iterations", std::to_string(shrink_iterations), ">= 0");
  }
  RequirePositive(huber, prefix + ".huber", "m");
  RequireNonNegative(tukey, prefix + ".tukey", "m");
  RequireNonNegative(min_rotation, prefix + ".min_rotation", "rad");
  RequireNonNegative(min_translation, prefix + ".min_translation", "m");
  RequirePositive(inlier_distance, prefix + ".inlier_distance", "m");
  RequireNonNegative(prior_rotation_deg, prefix + ".prior_rotation_deg", "deg");
  RequireNonNegative(prior_translation, prefix + ".prior_translation", "m");
}

namespace {

// Rejection distance at iteration k.
float DistanceAt(const IcpOptions& o, int k) {
  if (k >= o.shrink_iterations || o.shrink_iterations == 0)
    return static_cast<float>(o.end_distance);
  const double ratio = o.end_distance / o.start_distance;
  return static_cast<float>(o.start_distance *
                            std::pow(ratio, static_cast<double>(k) / o.shrink_iterations));
}

}  // namespace

IcpResult AlignPointToPlane(const ProxyModel& model, std::span<const Eigen::Vector3f> points,
                            size_t scored, double extra_distance, const Rigid3& proxy_T_camera,
                            const IcpOptions& options, std::span<const uint8_t> sample_matches) {
  IcpResult result;
  internal::PoseUpdate update(proxy_T_camera, options.huber,
                              options.prior_rotation_deg * M_PI / 180, options.prior_translation);
  const auto& model_points = model.points();
  const auto& model_normals = model.normals();
  const float huber = static_cast<float>(options.huber);
  const float extra = static_cast<float>(extra_distance);
  const float tukey = static_cast<float>(options.tukey);
  scored = std::min(scored, points.size());
  const bool colour = !sample_matches.empty();
  const uint8_t* matches = sample_matches.data();
  for (int k = 0; k < options.max_iterations; ++k) {
    const float limit = DistanceAt(options, k);
    const Eigen::Matrix3f r = update.rotation.cast<float>();
    const Eigen::Vector3f t = update.translation.cast<float>();
    internal::NormalEquations equations(huber);
    const size_t fitted = options.fit_extra_points ? points.size() : scored;
    for (size_t i = 0; i < fitted; ++i) {
      const Eigen::Vector3f rp = r * points[i];
      const Eigen::Vector3f s = rp + t;
      const int c = model.Closest(s);
      if (c < 0) continue;
      if (colour && !(matches[c] & (i < scored ? kMatchesScored : kMatchesExtra))) continue;
      const Eigen::Vector3f& n = model_normals[c];
      if (n.dot(rp) >= 0) continue;  // the model surface faces away from the camera
      const Eigen::Vector3f d = s - model_points[c];
      const float max_distance = i < scored ? limit : std::min(limit, extra);
      if (d.squaredNorm() > max_distance * max_distance) continue;
      const float residual = n.dot(d);
      if (tukey > 0) {
        const float z = points[i].z();
        const float c = tukey * z * z;
        const float u = residual / c;
        if (u * u < 1) equations.AddWeighted(s, n, residual, (1 - u * u) * (1 - u * u));
      } else {
        equations.Add(s, n, residual);
      }
    }
    result.iterations = k + 1;
    if (equations.used() < 6) break;
    double angle = 0.0, shift = 0.0;
    if (!update.Apply(equations, &angle, &shift)) break;
    if (k + 1 >= options.shrink_iterations && angle < options.min_rotation &&
        shift < options.min_translation) {
      break;
    }
  }
  // Re-orthonormalise and score.
  const Eigen::Quaterniond q = Eigen::Quaterniond(update.rotation).normalized();
  result.proxy_T_camera = Rigid3(q, update.translation);
  const Eigen::Matrix3f r = q.toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = update.translation.cast<float>();
  const float inlier = static_cast<float>(options.inlier_distance);
  const float extra_inlier = std::min(inlier, extra);
  double sum = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f rp = r * points[i];
    const Eigen::Vector3f s = rp + t;
    const int c = model.Closest(s);
    if (c < 0) continue;
    if (colour && !(matches[c] & (i < scored ? kMatchesScored : kMatchesExtra))) continue;
    const Eigen::Vector3f& n = model_normals[c];
    if (n.dot(rp) >= 0) continue;
    const Eigen::Vector3f d = s - model_points[c];
    if (i >= scored) {
      result.extra_inliers += d.squaredNorm() <= extra_inlier * extra_inlier;
      continue;
    }
    if (d.squaredNorm() > inlier * inlier) continue;
    const float residual = n.dot(d);
    sum += static_cast<double>(residual) * residual;
    ++result.inliers;
  }
  result.inlier_share = scored > 0 ? static_cast<double>(result.inliers) / scored : 0.0;
  result.rms = result.inliers > 0 ? std::sqrt(sum / result.inliers) : 0.0;
  return result;
}

}  // namespace mmh::track
