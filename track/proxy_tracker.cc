#include "track/proxy_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace mmh::track {

const char* TrackStatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::kTracked:
      return "tracked";
    case TrackStatus::kPredicted:
      return "predicted";
    case TrackStatus::kLost:
      return "lost";
  }
  return "?";
}

void DetectionOptions::Validate(const std::string& prefix) const {
  if (yaw_steps < 1 || yaw_steps > 360) {
    ThrowBadValue(prefix + ".yaw_steps", std::to_string(yaw_steps), "an integer in [1, 360]");
  }
  if (coarse_points < 10) {
    ThrowBadValue(prefix + ".coarse_points", std::to_string(coarse_points), ">= 10");
  }
  if (coarse_iterations < 1) {
    ThrowBadValue(prefix + ".coarse_iterations", std::to_string(coarse_iterations), ">= 1");
  }
  if (candidates < 1) ThrowBadValue(prefix + ".candidates", std::to_string(candidates), ">= 1");
  RequirePositive(coarse_start_distance, prefix + ".coarse_start_distance", "m");
  RequirePositive(coarse_end_distance, prefix + ".coarse_end_distance", "m");
  if (coarse_end_distance > coarse_start_distance) {
    ThrowBadValue(prefix + ".coarse_end_distance", FormatNumber(coarse_end_distance),
                  "at most coarse_start_distance");
  }
}

void VerificationOptions::Validate(const std::string& prefix) const {
  if (min_points < 6) ThrowBadValue(prefix + ".min_points", std::to_string(min_points), ">= 6");
  RequireProbability(min_inlier_share, prefix + ".min_inlier_share");
  RequirePositive(max_rms, prefix + ".max_rms", "m");
  RequireProbability(max_free_space_violation, prefix + ".max_free_space_violation");
  RequirePositive(free_space_margin, prefix + ".free_space_margin", "m");
  RequireNonNegative(play_area_margin, prefix + ".play_area_margin", "m");
  if (max_predicted_frames < 0) {
    ThrowBadValue(prefix + ".max_predicted_frames", std::to_string(max_predicted_frames), ">= 0");
  }
  RequireNonNegative(skin_distance, prefix + ".skin_distance", "m");
  if (max_points < min_points) {
    ThrowBadValue(prefix + ".max_points", std::to_string(max_points), ">= min_points");
  }
}

void ProxyTrackerOptions::Validate(const std::string& prefix) const {
  table.Validate(prefix + ".table");
  segmentation.Validate(prefix + ".segmentation");
  model.Validate(prefix + ".model");
  icp.Validate(prefix + ".icp");
  detection.Validate(prefix + ".detection");
  verification.Validate(prefix + ".verification");
}

struct ProxyTracker::Candidate {
  IcpResult icp;
  double free_space_violation = 0.0;
  bool good = false;
  std::string reason;
  double Score() const { return icp.inlier_share - free_space_violation; }
};

ProxyTracker::ProxyTracker(const TriangleMesh& model, const std::string& model_name,
                           const TrackSetup& setup, const ProxyTrackerOptions& options)
    : options_(options), setup_(setup), segmenter_(options.segmentation, setup) {
  options_.Validate("tracker");
  setup_.Validate("setup");
  model_ = std::make_unique<ProxyModel>(model, options_.model, model_name);
}

ProxyTracker::~ProxyTracker() = default;

TrackFrameResult ProxyTracker::Unreadable(const RgbdFrame& frame, const std::string& error) {
  TrackFrameResult result;
  result.index = frame.index;
  result.timestamp = frame.timestamp;
  result.reason = "unreadable frame: " + error;
  last_.reset();
  velocity_.reset();
  return result;
}

bool ProxyTracker::EnsureTable(const RgbdFrame& frame, std::string* why) {
  if (camera_T_table_) return true;
  table_plane_ = EstimateTablePlane(frame, options_.table, setup_.camera_T_table, why);
  if (!table_plane_) {
    *why = "no table plane: " + *why;
    return false;
  }
  camera_T_table_ = TableFrameOnPlane(*table_plane_, setup_.camera_T_table);
  segmenter_.SetTable(*camera_T_table_, frame.depth_intrinsics);
  return true;
}

ImageRect ProxyTracker::ProxyImage(const Rigid3& camera_T_proxy) const {
  const PinholeIntrinsics& k = *intrinsics_;
  const Eigen::Vector3d c = camera_T_proxy * model_->center().cast<double>();
  if (c.z() < 0.1) return {0, 0, k.width, k.height};
  const Eigen::Vector2d uv = k.Project(c);
  const double r = (model_->radius() + 0.02) * k.fx / c.z() + 4;
  return {std::clamp(static_cast<int>(uv.x() - r), 0, k.width),
          std::clamp(static_cast<int>(uv.y() - r), 0, k.height),
          std::clamp(static_cast<int>(uv.x() + r) + 1, 0, k.width),
          std::clamp(static_cast<int>(uv.y() + r) + 1, 0, k.height)};
}

double ProxyTracker::FreeSpaceViolation(const RgbdFrame& frame,
                                        const Rigid3& camera_T_proxy) const {
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const Eigen::Matrix3f r = camera_T_proxy.rotation.toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = camera_T_proxy.translation.cast<float>();
  const float margin = static_cast<float>(options_.verification.free_space_margin);
  int seen = 0, violations = 0;
  for (int i : model_->sparse_samples()) {
    const Eigen::Vector3f c = r * model_->points()[i] + t;
    if (c.z() <= 0.05f || (r * model_->normals()[i]).dot(c) >= 0) continue;
    const int u = static_cast<int>(std::lround(k.fx * c.x() / c.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * c.y() / c.z() + k.cy));
    if (u < 0 || v < 0 || u >= k.width || v >= k.height) continue;
    const uint16_t d = frame.depth[static_cast<size_t>(v) * k.width + u];
    if (d == 0) continue;
    ++seen;
    if (d * static_cast<float>(frame.depth_scale) > c.z() + margin) ++violations;
  }
  return seen > 0 ? static_cast<double>(violations) / seen : 1.0;
}

ProxyTracker::Candidate ProxyTracker::Verify(const RgbdFrame& frame, const IcpResult& icp) const {
  const VerificationOptions& o = options_.verification;
  Candidate candidate;
  candidate.icp = icp;
  const Rigid3 camera_T_proxy = icp.proxy_T_camera.Inverse();
  candidate.free_space_violation = FreeSpaceViolation(frame, camera_T_proxy);
  const Eigen::Vector3d table_c =
      camera_T_table_->Inverse() * (camera_T_proxy * model_->center().cast<double>());
  auto text = [](double value) { return FormatNumber(std::round(value * 1e4) / 1e4); };
  if (icp.inlier_share < o.min_inlier_share) {
    candidate.reason = "inlier share " + text(icp.inlier_share) + " < " + text(o.min_inlier_share);
  } else if (icp.rms > o.max_rms) {
    candidate.reason =
        "residual " + text(icp.rms * 1000) + " mm > " + text(o.max_rms * 1000) + " mm";
  } else if (candidate.free_space_violation > o.max_free_space_violation) {
    candidate.reason = "free-space violation " + text(candidate.free_space_violation) + " > " +
                       text(o.max_free_space_violation);
  } else if (std::abs(table_c.x()) > setup_.play_area_width / 2 + o.play_area_margin ||
             std::abs(table_c.y()) > setup_.play_area_depth / 2 + o.play_area_margin ||
             table_c.z() > options_.segmentation.max_height + o.play_area_margin ||
             table_c.z() < -o.play_area_margin) {
    candidate.reason = "out of the play area";
  } else {
    candidate.good = true;
  }
  return candidate;
}

std::optional<ProxyTracker::Candidate> ProxyTracker::Detect(const RgbdFrame& frame) {
  const DetectionOptions& o = options_.detection;
  // The largest segment (component 0), evenly subsampled.
  std::vector<Eigen::Vector3f> segment;
  for (size_t i = 0; i < segmentation_.points.size(); ++i) {
    if (segmentation_.components[i] == 0) segment.push_back(segmentation_.points[i]);
  }
  if (static_cast<int>(segment.size()) < options_.verification.min_points) return std::nullopt;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : segment) centroid += p;
  centroid /= static_cast<float>(segment.size());
  std::vector<Eigen::Vector3f> coarse;
  const size_t stride = std::max<size_t>(1, segment.size() / o.coarse_points);
  for (size_t i = 0; i < segment.size(); i += stride) coarse.push_back(segment[i]);

  // Orientations: the model's +z, -z, +x, -x, +y, -y up, each at yaw_steps yaws about the table
  // normal.
  const Eigen::Quaterniond camera_R_table = camera_T_table_->rotation;
  const double pi = std::numbers::pi;
  std::vector<Eigen::Quaterniond> ups = {Eigen::Quaterniond::Identity()};
  if (o.all_faces_up) {
    ups.emplace_back(Eigen::AngleAxisd(pi, Eigen::Vector3d::UnitX()));
    ups.emplace_back(Eigen::AngleAxisd(pi / 2, Eigen::Vector3d::UnitY()));
    ups.emplace_back(Eigen::AngleAxisd(-pi / 2, Eigen::Vector3d::UnitY()));
    ups.emplace_back(Eigen::AngleAxisd(pi / 2, Eigen::Vector3d::UnitX()));
    ups.emplace_back(Eigen::AngleAxisd(-pi / 2, Eigen::Vector3d::UnitX()));
  }
  // The visible surface is about a third of the model's radius nearer than its centre.
  const Eigen::Vector3d ray = centroid.cast<double>().normalized();
  const Eigen::Vector3d center_guess = centroid.cast<double>() + 0.35 * model_->radius() * ray;
  IcpOptions coarse_icp = options_.icp;
  coarse_icp.max_iterations = o.coarse_iterations;
  coarse_icp.start_distance = o.coarse_start_distance;
  coarse_icp.end_distance = o.coarse_end_distance;
  coarse_icp.shrink_iterations = std::max(1, o.coarse_iterations - 2);
  std::vector<IcpResult> coarse_results;
  for (const Eigen::Quaterniond& up : ups) {
    for (int k = 0; k < o.yaw_steps; ++k) {
      const Eigen::Quaterniond yaw(
          Eigen::AngleAxisd(2 * pi * k / o.yaw_steps, Eigen::Vector3d::UnitZ()));
      const Eigen::Quaterniond camera_R_proxy = (camera_R_table * yaw * up).normalized();
      const Rigid3 camera_T_proxy(camera_R_proxy,
                                  center_guess - camera_R_proxy * model_->center().cast<double>());
      coarse_results.push_back(AlignPointToPlane(*model_, coarse, coarse.size(), 0.0,
                                                 camera_T_proxy.Inverse(), coarse_icp));
    }
  }
  std::vector<size_t> order(coarse_results.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (coarse_results[a].inlier_share != coarse_results[b].inlier_share) {
      return coarse_results[a].inlier_share > coarse_results[b].inlier_share;
    }
    return coarse_results[a].rms < coarse_results[b].rms;
  });
  std::optional<Candidate> best;
  for (int c = 0; c < std::min<int>(o.candidates, static_cast<int>(order.size())); ++c) {
    const IcpResult refined =
        AlignPointToPlane(*model_, data_, scored_, options_.verification.skin_distance,
                          coarse_results[order[c]].proxy_T_camera, options_.icp);
    Candidate candidate = Verify(frame, refined);
    if (!best || (candidate.good && !best->good) ||
        (candidate.good == best->good && candidate.Score() > best->Score())) {
      best = candidate;
    }
  }
  return best;
}

TrackFrameResult ProxyTracker::Track(const RgbdFrame& frame) {
  TrackFrameResult result;
  result.index = frame.index;
  result.timestamp = frame.timestamp;
  auto lose = [&](const std::string& reason) {
    result.status = TrackStatus::kLost;
    result.reason = reason;
    last_.reset();
    velocity_.reset();
    predicted_frames_ = 0;
    return result;
  };
  // The frame itself.
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  if (frame.depth.size() != static_cast<size_t>(k.width) * k.height || k.width <= 0 ||
      k.height <= 0) {
    return lose("depth has " + std::to_string(frame.depth.size()) + " pixels, expected " +
                std::to_string(k.width) + "x" + std::to_string(k.height) + " (its intrinsics)");
  }
  if (!(frame.depth_scale > 0) || !std::isfinite(frame.depth_scale)) {
    return lose("depth_scale " + FormatNumber(frame.depth_scale) + " is not a positive number");
  }
  if (intrinsics_ && !(*intrinsics_ == k)) {
    return lose("frame size or intrinsics differ from the first frame's (" +
                std::to_string(k.width) + "x" + std::to_string(k.height) + " vs " +
                std::to_string(intrinsics_->width) + "x" + std::to_string(intrinsics_->height) +
                ")");
  }
  if (!intrinsics_) {
    try {
      k.Validate("frame intrinsics");
    } catch (const InputError& e) {
      return lose(e.what());
    }
  }
  std::string why;
  if (std::none_of(frame.depth.begin(), frame.depth.end(), [](uint16_t d) { return d != 0; })) {
    return lose("depth all missing");
  }
  if (!EnsureTable(frame, &why)) return lose(why);
  intrinsics_ = k;

  segmenter_.Segment(frame, &segmentation_);
  result.points = static_cast<int>(segmentation_.points.size());
  result.skin_points = static_cast<int>(segmentation_.skin_points.size());
  // ICP data: the segmented points evenly subsampled, then the skin points.
  data_.clear();
  const size_t stride =
      std::max<size_t>(1, (segmentation_.points.size() + options_.verification.max_points - 1) /
                              options_.verification.max_points);
  for (size_t i = 0; i < segmentation_.points.size(); i += stride)
    data_.push_back(segmentation_.points[i]);
  scored_ = data_.size();
  for (size_t i = 0; i < segmentation_.skin_points.size(); i += stride) {
    data_.push_back(segmentation_.skin_points[i]);
  }

  const bool enough = result.points >= options_.verification.min_points;
  std::optional<Candidate> chosen;
  if (last_ && enough) {
    const Rigid3 predicted = velocity_ ? *velocity_ * *last_ : *last_;
    const IcpResult icp =
        AlignPointToPlane(*model_, data_, scored_, options_.verification.skin_distance,
                          predicted.Inverse(), options_.icp);
    Candidate candidate = Verify(frame, icp);
    if (candidate.good) {
      chosen = candidate;
    } else {
      why = candidate.reason;
    }
  }
  if (!chosen && enough) {
    std::optional<Candidate> detected = Detect(frame);
    if (detected && detected->good) {
      chosen = detected;
      result.detected = true;
    } else if (why.empty()) {
      why = detected ? "no pose hypothesis verified (best: " + detected->reason + ")"
                     : "no segment large enough for a detection";
    }
  }
  if (chosen) {
    const Rigid3 camera_T_proxy = chosen->icp.proxy_T_camera.Inverse();
    if (last_ && !result.detected) {
      velocity_ = camera_T_proxy * last_->Inverse();
    } else {
      velocity_.reset();
    }
    last_ = camera_T_proxy;
    predicted_frames_ = 0;
    result.status = TrackStatus::kTracked;
    result.camera_T_proxy = camera_T_proxy;
    result.inlier_share = chosen->icp.inlier_share;
    result.rms = chosen->icp.rms;
    result.free_space_violation = chosen->free_space_violation;
    result.iterations = chosen->icp.iterations;
    segmenter_.UpdateBackground(frame, ProxyImage(camera_T_proxy));
    return result;
  }
  if (!enough) {
    why = "too few proxy points (" + std::to_string(result.points) + " < " +
          std::to_string(options_.verification.min_points) + ")";
    if (last_ && predicted_frames_ < options_.verification.max_predicted_frames) {
      // Extrapolate, slowing down: a hidden proxy is more likely to stop than to fly on.
      if (velocity_) velocity_ = Interpolate(Rigid3::Identity(), *velocity_, 0.5);
      last_ = velocity_ ? *velocity_ * *last_ : *last_;
      ++predicted_frames_;
      result.status = TrackStatus::kPredicted;
      result.camera_T_proxy = *last_;
      result.reason = why;
      return result;
    }
  }
  return lose(why);
}

}  // namespace mmh::track
