#include "track/proxy_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace mmh::track {

struct ProxyTracker::Candidate {
  IcpResult icp;
  double free_space_violation = 0.0;
  double explained = 0.0;
  double penetration = 0.0;
  bool good = false;
  std::string reason;
  // Ranks verified poses: the data the model explains (segmented and skin-coloured points within
  // reach of its surface, per segmented point), less twice the share of the model surfaces the
  // camera sees through. Near-symmetric proxies (the Soldier's body is
  // symmetric under a half turn; only its rifle is not) are told apart by both. (The share of the
  // model the data confirms is no guide: the hand in front of the model confirms a wrong pose.)
  // The skin-coloured points count up to max_skin_evidence (VerificationOptions).
  double max_skin_evidence = 1.0;
  double Score() const {
    if (icp.inliers <= 0) return -2 * free_space_violation;
    const double scored = icp.inliers / icp.inlier_share;
    return icp.inlier_share + std::min(icp.extra_inliers / scored, max_skin_evidence) -
           2 * free_space_violation;
  }
};

ProxyTracker::ProxyTracker(const TriangleMesh& model, const std::string& model_name,
                           const TrackSetup& setup, const ProxyTrackerOptions& options)
    : options_(options),
      setup_(setup),
      segmenter_(options.segmentation, setup),
      output_filter_(options.output_filter) {
  options_.Validate("tracker");
  setup_.Validate("setup");
  model_ = std::make_unique<ProxyModel>(model, options_.model, model_name);
  motion_.emplace(options_.motion, model_->centroid().cast<double>(), model_->radius());
  search_icp_ = options_.icp;
  search_icp_.prior_rotation_deg = 0;
  search_icp_.prior_translation = 0;
  // Colour consistency: which samples may match skin-coloured and which other points. A face's
  // colour is tested with the segmentation's skin box (OpenCV's RGB -> YCrCb, ITU-R BT.601) under
  // shading from 0.3 to 1.3 times its albedo: a face that is skin-coloured under some shading may
  // match skin points, one that is not under some shading may match the others (the Soldier's
  // red tunic is skin-coloured in shadow only; its head, light nougat, is not when brightly lit).
  const SegmentationOptions& so = options_.segmentation;
  if (options_.verification.colour_matching && so.skin && model.face_colors.rows() > 0) {
    std::vector<uint8_t> face_matches(model.face_count(), 0);
    for (int f = 0; f < model.face_count(); ++f) {
      for (int shade = 3; shade <= 13; ++shade) {
        double rgb[3];
        for (int c = 0; c < 3; ++c)
          rgb[c] = std::min(255.0, model.face_colors(f, c) * shade / 10.0);
        const double y = 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2];
        const double cr = (rgb[0] - y) * 0.713 + 128, cb = (rgb[2] - y) * 0.564 + 128;
        const bool skin = cr >= so.skin_cr_min && cr <= so.skin_cr_max && cb >= so.skin_cb_min &&
                          cb <= so.skin_cb_max;
        face_matches[f] |= skin ? kMatchesExtra : kMatchesScored;
      }
    }
    sample_matches_.reserve(model_->points().size());
    for (int f : model_->sample_faces()) sample_matches_.push_back(face_matches[f]);
  }
}

ProxyTracker::~ProxyTracker() = default;

void ProxyTracker::Initialize(const Rigid3& camera_T_proxy) {
  motion_->Reset();
  output_filter_.Reset();
  reacquire_pose_.reset();
  motion_->Measure(camera_T_proxy, false);
  predicted_frames_ = 0;
  tracked_frames_ = 0;
  frames_since_detection_ = 0;
}

TrackFrameResult ProxyTracker::Unreadable(const RgbdFrame& frame, const std::string& error) {
  TrackFrameResult result;
  result.index = frame.index;
  result.timestamp = frame.timestamp;
  output_filter_.Reset();
  return Lose(result, "unreadable frame: " + error);
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

ImageRect ProxyTracker::ProxyImage(const Rigid3& camera_T_proxy, double margin) const {
  const PinholeIntrinsics& k = *intrinsics_;
  const Eigen::Vector3d c = camera_T_proxy * model_->center().cast<double>();
  if (c.z() < 0.1) return {0, 0, k.width, k.height};
  const Eigen::Vector2d uv = k.Project(c);
  const double r = (model_->radius() + margin) * k.fx / c.z() + 4;
  return {std::clamp(static_cast<int>(uv.x() - r), 0, k.width),
          std::clamp(static_cast<int>(uv.y() - r), 0, k.height),
          std::clamp(static_cast<int>(uv.x() + r) + 1, 0, k.width),
          std::clamp(static_cast<int>(uv.y() + r) + 1, 0, k.height)};
}

ProxyTracker::Visibility ProxyTracker::ModelVisibility(const RgbdFrame& frame,
                                                       const Rigid3& camera_T_proxy) const {
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const Eigen::Matrix3f r = camera_T_proxy.rotation.toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = camera_T_proxy.translation.cast<float>();
  const float margin = static_cast<float>(options_.verification.free_space_margin);
  // The table's up direction and a point on it, camera frame: a sample's height is up . (c - o).
  const Eigen::Vector3f up = (camera_T_table_->rotation * Eigen::Vector3d::UnitZ()).cast<float>();
  const float up_offset = up.dot(camera_T_table_->translation.cast<float>());
  float lowest = 0.0f;
  int seen = 0, violations = 0, explained = 0;
  for (int i : model_->sparse_samples()) {
    const Eigen::Vector3f c = r * model_->points()[i] + t;
    lowest = std::min(lowest, up.dot(c) - up_offset);
    if (c.z() <= 0.05f || (r * model_->normals()[i]).dot(c) >= 0) continue;
    // Rounded to the nearest pixel; std::lround is a library call, and for the coordinates kept
    // (x >= -0.5) floor(x + 0.5) rounds the same.
    const double x = k.fx * c.x() / c.z() + k.cx + 0.5;
    const double y = k.fy * c.y() / c.z() + k.cy + 0.5;
    if (!(x >= 0 && y >= 0 && x < k.width && y < k.height)) continue;
    const int u = static_cast<int>(x), v = static_cast<int>(y);
    const uint16_t d = frame.depth[static_cast<size_t>(v) * k.width + u];
    if (d == 0) continue;
    ++seen;
    const float z = d * static_cast<float>(frame.depth_scale);
    if (z > c.z() + margin) {
      ++violations;
    } else if (z >= c.z() - margin) {
      ++explained;
    }
  }
  Visibility visibility;
  visibility.violation = seen > 0 ? static_cast<double>(violations) / seen : 1.0;
  visibility.explained = seen > 0 ? static_cast<double>(explained) / seen : 0.0;
  visibility.penetration = -lowest;
  return visibility;
}

ProxyTracker::Candidate ProxyTracker::Verify(const RgbdFrame& frame, const IcpResult& icp) const {
  const VerificationOptions& o = options_.verification;
  Candidate candidate;
  candidate.icp = icp;
  candidate.max_skin_evidence = o.max_skin_evidence;
  const Rigid3 camera_T_proxy = icp.proxy_T_camera.Inverse();
  const Visibility visibility = ModelVisibility(frame, camera_T_proxy);
  candidate.free_space_violation = visibility.violation;
  candidate.explained = visibility.explained;
  candidate.penetration = visibility.penetration;
  const Eigen::Vector3d table_c =
      camera_T_table_->Inverse() * (camera_T_proxy * model_->center().cast<double>());
  auto text = [](double value) { return FormatNumber(std::round(value * 1e4) / 1e4); };
  // Judged by the interior points when the outline is flagged (segmentation.outline_span): the
  // same pose scored, without moving it, on the points no straddling window reaches.
  double inlier_share = icp.inlier_share, rms = icp.rms;
  if (!interior_.empty()) {
    IcpOptions score_only = search_icp_;
    score_only.max_iterations = 0;
    const IcpResult interior =
        AlignPointToPlane(*model_, interior_, interior_.size(), o.skin_distance, icp.proxy_T_camera,
                          score_only, sample_matches_);
    inlier_share = interior.inlier_share;
    rms = interior.rms;
  }
  if (inlier_share < o.min_inlier_share) {
    candidate.reason = "inlier share " + text(inlier_share) + " < " + text(o.min_inlier_share);
  } else if (rms > o.max_rms) {
    candidate.reason = "residual " + text(rms * 1000) + " mm > " + text(o.max_rms * 1000) + " mm";
  } else if (candidate.free_space_violation > o.max_free_space_violation) {
    candidate.reason = "free-space violation " + text(candidate.free_space_violation) + " > " +
                       text(o.max_free_space_violation);
  } else if (candidate.penetration > o.max_penetration) {
    candidate.reason = "the model reaches " + text(candidate.penetration * 1000) +
                       " mm into the table > " + text(o.max_penetration * 1000) + " mm";
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

std::vector<IcpResult> ProxyTracker::CoarseHypotheses(const IcpOptions& coarse_icp,
                                                      size_t* scored) const {
  const DetectionOptions& o = options_.detection;
  // The largest segment (component 0), evenly subsampled.
  std::vector<Eigen::Vector3f> segment;
  for (size_t i = 0; i < segmentation_.points.size(); ++i) {
    if (segmentation_.components[i] == 0) segment.push_back(segmentation_.points[i]);
  }
  if (static_cast<int>(segment.size()) < options_.verification.min_points) return {};
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  for (const auto& p : segment) centroid += p;
  centroid /= static_cast<float>(segment.size());
  std::vector<Eigen::Vector3f> coarse;
  const size_t stride = std::max<size_t>(1, segment.size() / o.coarse_points);
  for (size_t i = 0; i < segment.size(); i += stride) coarse.push_back(segment[i]);
  const size_t coarse_scored = coarse.size();
  *scored = coarse_scored;
  // Skin-coloured points as many again at most: they count where they lie on the model (a
  // skin-coloured head or part tells a pose from its near-symmetric twins).
  const size_t skin_stride =
      std::max<size_t>(1, segmentation_.skin_points.size() / std::max<size_t>(1, coarse_scored));
  for (size_t i = 0; i < segmentation_.skin_points.size(); i += skin_stride) {
    coarse.push_back(segmentation_.skin_points[i]);
  }

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
  std::vector<IcpResult> coarse_results;
  for (const Eigen::Quaterniond& up : ups) {
    for (int k = 0; k < o.yaw_steps; ++k) {
      const Eigen::Quaterniond yaw(
          Eigen::AngleAxisd(2 * pi * k / o.yaw_steps, Eigen::Vector3d::UnitZ()));
      const Eigen::Quaterniond camera_R_proxy = (camera_R_table * yaw * up).normalized();
      const Rigid3 camera_T_proxy(camera_R_proxy,
                                  center_guess - camera_R_proxy * model_->center().cast<double>());
      coarse_results.push_back(
          AlignPointToPlane(*model_, coarse, coarse_scored, options_.verification.skin_distance,
                            camera_T_proxy.Inverse(), coarse_icp, sample_matches_));
    }
  }
  return coarse_results;
}

// The state of one detection: the best candidate so far, the distinct poses refined, and the
// verified poses (proxy_T_camera) with their scores (for the rival).
struct ProxyTracker::DetectionRanking {
  std::optional<Rigid3> predicted;
  std::optional<Candidate> best;
  // verified's index of best (nullopt while best is not verified, or after it is replaced).
  std::optional<size_t> best_verified;
  std::vector<Rigid3> refined_poses;
  std::vector<Candidate> verified;
  // verified[i]'s colour agreement, computed once (VerifiedAgreement): the appearance check and
  // the rival's choice both ask for it, and each computation projects every face of the coloured
  // model (16 384 for the gelatin box's scan) and averages a window of pixels at each.
  struct Agreement {
    bool computed = false;
    std::optional<double> value;
  };
  std::vector<Agreement> agreements;
};

namespace {

// Hypotheses converge to a few poses: each counts once.
bool SamePose(const Rigid3& a, const Rigid3& b) {
  return RotationAngle(a.rotation, b.rotation) < 0.1 && (a.translation - b.translation).norm() < 0.01;
}

}  // namespace

IcpOptions ProxyTracker::CoarseIcpOptions() const {
  const DetectionOptions& o = options_.detection;
  IcpOptions coarse_icp = search_icp_;
  coarse_icp.max_iterations = o.coarse_iterations;
  coarse_icp.start_distance = o.coarse_start_distance;
  coarse_icp.end_distance = o.coarse_end_distance;
  coarse_icp.shrink_iterations = std::max(1, o.coarse_iterations - 2);
  return coarse_icp;
}

std::vector<size_t> ProxyTracker::RankCoarse(const RgbdFrame& frame,
                                             const std::vector<IcpResult>& coarse_results,
                                             size_t coarse_scored) const {
  // Ranked as verified poses are ranked (track/proxy_tracker.h, Score).
  std::vector<double> scores(coarse_results.size());
  for (size_t i = 0; i < coarse_results.size(); ++i) {
    const Visibility visibility =
        ModelVisibility(frame, coarse_results[i].proxy_T_camera.Inverse());
    // A pose reaching into the table is impossible (verification rejects it): ranked last.
    scores[i] = static_cast<double>(coarse_results[i].inliers + coarse_results[i].extra_inliers) /
                    coarse_scored -
                2 * visibility.violation -
                (visibility.penetration > options_.verification.max_penetration ? 10.0 : 0.0);
  }
  std::vector<size_t> order(coarse_results.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return scores[a] > scores[b]; });
  return order;
}

bool ProxyTracker::Better(const Candidate& a, const std::optional<Candidate>& b,
                          const std::optional<Rigid3>& predicted) const {
  // Verified beats unverified; then the score, except that among poses scoring within
  // switch_margin of each other the one nearer the prediction wins (when the views of a
  // near-symmetric proxy cannot tell its twins apart, continuity can), and within
  // far_switch_margin when they are more than 45 deg apart and the track is trusted (a twin: the
  // Soldier's half turn differs only by its rifle, which the hand often hides).
  const DetectionOptions& o = options_.detection;
  if (!b) return true;
  if (a.good != b->good) return a.good;
  if (predicted) {
    auto distance_to_prediction = [&](const Candidate& c) {
      return RotationAngle(c.icp.proxy_T_camera.Inverse().rotation, predicted->rotation);
    };
    const double to_a = distance_to_prediction(a);
    const double to_b = distance_to_prediction(*b);
    // ... and only for a pose that continues the track (within 45 deg of the prediction): of two
    // poses both far from it (the proxy turned while it was lost), neither does.
    const bool far = tracked_frames_ >= o.trusted_frames &&
                     std::min(to_a, to_b) <= std::numbers::pi / 4 &&
                     RotationAngle(a.icp.proxy_T_camera.rotation, b->icp.proxy_T_camera.rotation) >
                         std::numbers::pi / 4;
    if (std::abs(a.Score() - b->Score()) <= (far ? o.far_switch_margin : o.switch_margin)) {
      return to_a < to_b;
    }
  }
  return a.Score() > b->Score();
}

void ProxyTracker::Weigh(const RgbdFrame& frame, const IcpResult& refined,
                         DetectionRanking* ranking) const {
  Candidate candidate = Verify(frame, refined);
  if (Better(candidate, ranking->best, ranking->predicted)) {
    ranking->best = candidate;
    ranking->best_verified.reset();
    if (candidate.good) ranking->best_verified = ranking->verified.size();
  }
  if (candidate.good) ranking->verified.push_back(candidate);
}

void ProxyTracker::WeighDistinct(const RgbdFrame& frame, const IcpResult& refined,
                                 DetectionRanking* ranking) const {
  for (const Rigid3& p : ranking->refined_poses) {
    if (SamePose(p, refined.proxy_T_camera)) return;
  }
  ranking->refined_poses.push_back(refined.proxy_T_camera);
  Weigh(frame, refined, ranking);
}

IcpResult ProxyTracker::RefineOnMedium(const Rigid3& proxy_T_camera, const IcpOptions& icp,
                                       size_t medium_scored) const {
  return AlignPointToPlane(*model_, detection_scratch_, medium_scored,
                           options_.verification.skin_distance, proxy_T_camera, icp,
                           sample_matches_);
}

std::vector<Rigid3> ProxyTracker::MotionSeeds(const std::optional<Rigid3>& predicted) const {
  // The motion model's poses are candidates too (the prediction and the last measured pose),
  // refined as the twins are: the coarse hypotheses sample yaw every 30 deg, and when a
  // near-symmetric twin scores as well as the truth (its distinguishing part under the hand), only
  // a well-refined candidate near the prediction lets continuity decide (Better).
  const DetectionOptions& o = options_.detection;
  std::vector<Rigid3> seeds;
  if (predicted) seeds.push_back(*predicted);
  const std::optional<Rigid3>& last = motion_->last();
  if (last && (!predicted || !(last->rotation.isApprox(predicted->rotation) &&
                               last->translation.isApprox(predicted->translation)))) {
    seeds.push_back(*last);
  }
  // ... and the prediction displaced: the tracked pose may sit in a nearby minimum the ICP cannot
  // leave (seen from the side under the hand, the figure slides along its vertical faces, or rolls
  // a few degrees), which the coarse hypotheses, 30 deg apart, need not reach either.
  if (predicted && o.seed_shift > 0) {
    const Eigen::Quaterniond camera_R_table = camera_T_table_->rotation;
    const Eigen::Vector3d up = camera_R_table * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d center = *predicted * model_->center().cast<double>();
    for (double sign : {-1.0, 1.0}) {
      seeds.emplace_back(predicted->rotation, predicted->translation + sign * o.seed_shift * up);
    }
    for (int axis = 0; axis < 2; ++axis) {
      for (double sign : {-1.0, 1.0}) {
        const Eigen::Quaterniond turn(
            Eigen::AngleAxisd(sign * o.seed_turn_deg * std::numbers::pi / 180,
                              camera_R_table * Eigen::Vector3d::Unit(axis)));
        seeds.emplace_back(turn * predicted->rotation,
                           center + turn * (predicted->translation - center));
      }
    }
  }
  return seeds;
}

void ProxyTracker::WeighTwins(const RgbdFrame& frame, const IcpOptions& coarse_icp,
                              size_t medium_scored, DetectionRanking* ranking) const {
  // Near-symmetric twins of the best pose: turned by quarter turns about the model's own axes
  // through its centre (a proxy built from bricks is often symmetric but for a small part, which
  // the coarse ranking cannot see).
  const Rigid3 camera_T_proxy = ranking->best->icp.proxy_T_camera.Inverse();
  const Eigen::Vector3d center = model_->centroid().cast<double>();
  const Candidate original = *ranking->best;
  for (int axis = 0; axis < 3; ++axis) {
    for (int quarter = 1; quarter <= 3; ++quarter) {
      // proxy_T_twin: the turn about the centre, in the model's frame.
      const Eigen::Quaterniond turn(
          Eigen::AngleAxisd(quarter * std::numbers::pi / 2, Eigen::Vector3d::Unit(axis)));
      const Rigid3 proxy_T_twin(turn, center - turn * center);
      // Coarse first (the turn about the centre need not be the symmetry's), then fine.
      const IcpResult coarse_twin =
          RefineOnMedium((camera_T_proxy * proxy_T_twin).Inverse(), coarse_icp, medium_scored);
      const IcpResult refined = RefineOnMedium(coarse_twin.proxy_T_camera, search_icp_, medium_scored);
      if (SamePose(refined.proxy_T_camera, original.icp.proxy_T_camera)) continue;
      Weigh(frame, refined, ranking);
    }
  }
}

void ProxyTracker::SetDetectionRival(const RgbdFrame& frame, DetectionRanking* ranking) {
  // The rival: the best-scoring verified pose more than 45 deg from the winner (a near-symmetric
  // twin that the data could not rule out), kept as the turn from the winner in the model's
  // frame (proxy_T_rival) and carried along with the track (Track: the twin evidence). A twin
  // whose colours agree min_gain worse than the winner's is ruled out (the appearance check).
  // The winner was refined on all the frame's data after the ranking: its agreement is at the
  // refined pose, the twins' are the ranking's.
  const Rigid3 camera_T_best = ranking->best->icp.proxy_T_camera.Inverse();
  const std::optional<double> best_appearance = AppearanceAgreement(frame, camera_T_best);
  detection_rival_.reset();
  double rival_score = 0.0;
  for (size_t i = 0; i < ranking->verified.size(); ++i) {
    const Candidate& candidate = ranking->verified[i];
    const Rigid3 camera_T_pose = candidate.icp.proxy_T_camera.Inverse();
    const double score = candidate.Score();
    if (RotationAngle(camera_T_pose.rotation, camera_T_best.rotation) <= std::numbers::pi / 4) {
      continue;
    }
    if (detection_rival_ && score <= rival_score) continue;
    if (best_appearance) {
      const std::optional<double> appearance = VerifiedAgreement(frame, i, ranking);
      if (appearance && *appearance < *best_appearance - options_.appearance.min_gain) continue;
    }
    detection_rival_ = camera_T_best.Inverse() * camera_T_pose;
    rival_score = score;
  }
}

std::optional<ProxyTracker::Candidate> ProxyTracker::Detect(const RgbdFrame& frame,
                                                            const std::optional<Rigid3>& predicted,
                                                            bool light) {
  const DetectionOptions& o = options_.detection;
  const IcpOptions coarse_icp = CoarseIcpOptions();
  // The coarse hypotheses (not in a light check: only the motion model's seeds and the twins).
  std::vector<IcpResult> coarse_results;
  size_t coarse_scored = 1;
  if (!light) {
    coarse_results = CoarseHypotheses(coarse_icp, &coarse_scored);
    // Without a segment large enough for them (a hand over the proxy breaks it into pieces), the
    // motion model's seeds alone, when there are any.
    if (coarse_results.empty() && !predicted) return std::nullopt;
  }
  const std::vector<size_t> order = RankCoarse(frame, coarse_results, coarse_scored);
  // Candidates are refined and ranked on at most refine_points segmented points (and the skin
  // points among data_ in proportion); only the winner is refined on all of them.
  const size_t medium_scored = PrepareMediumData();
  DetectionRanking ranking;
  ranking.predicted = predicted;
  for (const Rigid3& seed : MotionSeeds(predicted)) {
    const IcpResult coarse_seed = RefineOnMedium(seed.Inverse(), coarse_icp, medium_scored);
    WeighDistinct(frame, RefineOnMedium(coarse_seed.proxy_T_camera, search_icp_, medium_scored),
                  &ranking);
  }
  // The best coarse results, refined until `candidates` distinct poses besides the seeds'.
  const size_t seeded = ranking.refined_poses.size();
  for (size_t c = 0;
       c < order.size() &&
       static_cast<int>(ranking.refined_poses.size() - seeded) < o.candidates &&
       c < static_cast<size_t>(3 * o.candidates);
       ++c) {
    WeighDistinct(frame,
                  RefineOnMedium(coarse_results[order[c]].proxy_T_camera, search_icp_, medium_scored),
                  &ranking);
  }
  if (ranking.best && o.twins) WeighTwins(frame, coarse_icp, medium_scored, &ranking);
  if (ranking.best) ChooseByAppearance(frame, &ranking);
  if (ranking.best) {
    ranking.best = Verify(
        frame, AlignPointToPlane(*model_, data_, scored_, options_.verification.skin_distance,
                                 ranking.best->icp.proxy_T_camera, search_icp_, sample_matches_));
    ranking.best_verified.reset();  // refined: no longer the verified pose
    SetDetectionRival(frame, &ranking);
  }
  return ranking.best;
}

std::optional<ProxyTracker::Candidate> ProxyTracker::DetectAmongSegments(
    const RgbdFrame& frame, const std::optional<Rigid3>& predicted) {
  const DetectionOptions& o = options_.detection;
  const Segmentation whole = segmentation_;
  // A segment's points: at most the model's diameter apart (its bounding box's diagonal, plus
  // the slack for depth noise and flying pixels at its edges).
  const double max_extent = 2 * model_->radius() + o.segment_slack;
  std::optional<Candidate> best;
  double best_rank = 0.0;
  std::optional<Segmentation> best_segment;
  std::optional<Rigid3> best_rival;
  int tried = 0;
  for (size_t c = 0; c < whole.component_sizes.size() && tried < o.model_segments; ++c) {
    Segmentation segment;
    const bool flagged = whole.outline.size() == whole.points.size();
    for (size_t i = 0; i < whole.points.size(); ++i) {
      if (whole.components[i] != static_cast<int>(c)) continue;
      segment.points.push_back(whole.points[i]);
      segment.components.push_back(0);
      if (flagged) segment.outline.push_back(whole.outline[i]);
    }
    if (static_cast<int>(segment.points.size()) < options_.verification.min_points) break;
    Eigen::AlignedBox3f box;
    for (const auto& p : segment.points) box.extend(p);
    if (box.diagonal().norm() > max_extent) continue;
    ++tried;
    segment.component_sizes = {whole.component_sizes[c]};
    segmentation_ = segment;
    PrepareData();
    std::optional<Candidate> candidate = Detect(frame, predicted, false);
    if (!candidate) continue;
    if (o.own_segment_share > 0) {
      // Scored as tracking will score it (own_segment_share): on all of the frame's segments that
      // lie on the model at this pose, refined there. An object seen as several segments (the
      // mug's outer wall and its inside, split at the rim by segmentation.max_depth_jump) is
      // then ranked on all of them, not on the part one segment shows.
      segmentation_ = whole;
      KeepOwnSegments(candidate->icp.proxy_T_camera.Inverse());
      PrepareData();
      if (static_cast<int>(data_.size()) >= options_.verification.min_points) {
        candidate = Verify(frame, AlignPointToPlane(*model_, data_, scored_,
                                                    options_.verification.skin_distance,
                                                    candidate->icp.proxy_T_camera, search_icp_,
                                                    sample_matches_));
        segment = segmentation_;
      }
    }
    // The inlier share is of this segment's points, which a pose on a small part of another
    // object also explains: the share of the model's visible surface that the depth confirms
    // tells the object that fills the model.
    const double rank = candidate->Score() + candidate->explained;
    const bool better = !best || (candidate->good && !best->good) ||
                        (candidate->good == best->good && rank > best_rank);
    if (better) {
      best = candidate;
      best_rank = rank;
      best_segment = segment;
      best_rival = detection_rival_;
    }
  }
  detection_rival_ = best_rival;
  segmentation_ = best_segment ? *best_segment : whole;
  PrepareData();
  return best;
}

ProxyTracker::PoseScore ProxyTracker::ScorePose(const RgbdFrame& frame,
                                                const Rigid3& camera_T_proxy) const {
  PoseScore score;
  if (!camera_T_table_) return score;
  const IcpResult icp =
      AlignPointToPlane(*model_, data_, scored_, options_.verification.skin_distance,
                        camera_T_proxy.Inverse(), search_icp_, sample_matches_);
  const Candidate candidate = Verify(frame, icp);
  score.camera_T_proxy = icp.proxy_T_camera.Inverse();
  score.inlier_share = icp.inlier_share;
  score.rms = icp.rms;
  score.free_space_violation = candidate.free_space_violation;
  score.explained = candidate.explained;
  score.score = candidate.Score();
  score.good = candidate.good;
  score.appearance = AppearanceAgreement(frame, score.camera_T_proxy);
  return score;
}

void ProxyTracker::SetAppearanceModel(std::shared_ptr<const AppearanceModel> appearance) {
  appearance_ = std::move(appearance);
}

std::optional<double> ProxyTracker::AppearanceAgreement(const RgbdFrame& frame,
                                                        const Rigid3& camera_T_proxy) const {
  if (!appearance_ || options_.appearance.margin <= 0) return std::nullopt;
  return appearance_->Agreement(frame, camera_T_proxy, options_.appearance);
}

std::optional<double> ProxyTracker::VerifiedAgreement(const RgbdFrame& frame, size_t i,
                                                      DetectionRanking* ranking) const {
  ranking->agreements.resize(ranking->verified.size());
  DetectionRanking::Agreement& agreement = ranking->agreements[i];
  if (!agreement.computed) {
    agreement.value = AppearanceAgreement(frame, ranking->verified[i].icp.proxy_T_camera.Inverse());
    agreement.computed = true;
  }
  return agreement.value;
}

void ProxyTracker::ChooseByAppearance(const RgbdFrame& frame, DetectionRanking* ranking) const {
  // The depth's winner stands unless a verified pose the depth scores as well (within margin)
  // shows the model's colours where the image has them, min_gain better than the winner does.
  // A verified winner is one of ranking->verified (Weigh).
  if (!ranking->best->good) return;
  const std::optional<double> best = VerifiedAgreement(frame, *ranking->best_verified, ranking);
  if (!best) return;
  const double best_score = ranking->best->Score();
  double chosen_agreement = *best + options_.appearance.min_gain;
  std::optional<size_t> chosen;
  for (size_t i = 0; i < ranking->verified.size(); ++i) {
    if (ranking->verified[i].Score() < best_score - options_.appearance.margin) continue;
    const std::optional<double> agreement = VerifiedAgreement(frame, i, ranking);
    if (agreement && *agreement > chosen_agreement) {
      chosen_agreement = *agreement;
      chosen = i;
    }
  }
  if (chosen) {
    ranking->best = ranking->verified[*chosen];
    ranking->best_verified = chosen;
  }
}

size_t ProxyTracker::PrepareMediumData() {
  const size_t refine_points = static_cast<size_t>(options_.detection.refine_points);
  std::vector<Eigen::Vector3f>& medium = detection_scratch_;
  medium.clear();
  const size_t stride = std::max<size_t>(1, (scored_ + refine_points - 1) / refine_points);
  for (size_t i = 0; i < scored_; i += stride) medium.push_back(data_[i]);
  const size_t medium_scored = medium.size();
  for (size_t i = scored_; i < data_.size(); i += stride) medium.push_back(data_[i]);
  return medium_scored;
}

void ProxyTracker::PrepareData() {
  // ICP data: the segmented points evenly subsampled, then the skin points.
  data_.clear();
  const size_t stride =
      std::max<size_t>(1, (segmentation_.points.size() + options_.verification.max_points - 1) /
                              options_.verification.max_points);
  interior_.clear();
  const bool flagged = segmentation_.outline.size() == segmentation_.points.size();
  for (size_t i = 0; i < segmentation_.points.size(); i += stride) {
    data_.push_back(segmentation_.points[i]);
    if (flagged && !segmentation_.outline[i]) interior_.push_back(segmentation_.points[i]);
  }
  scored_ = data_.size();
  if (!flagged || static_cast<int>(interior_.size()) < options_.verification.min_points) {
    interior_.clear();
  }
  // Skin points only within reach of the proxy (the segmented points' centroid plus the model's
  // radius and the ICP's start distance): most of the hand and forearm can never lie on the model
  // and would only cost time in every ICP iteration.
  if (scored_ > 0) {
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    for (size_t i = 0; i < scored_; ++i) centroid += data_[i];
    centroid /= static_cast<float>(scored_);
    const float reach = model_->radius() + static_cast<float>(options_.icp.start_distance);
    for (size_t i = 0; i < segmentation_.skin_points.size(); i += stride) {
      const Eigen::Vector3f& p = segmentation_.skin_points[i];
      if ((p - centroid).squaredNorm() <= reach * reach) data_.push_back(p);
    }
  }
}

void ProxyTracker::SetRival(const std::optional<Rigid3>& proxy_T_rival, bool reset_evidence) {
  if (!proxy_T_rival) {
    // No rival found: a structural twin stays one (keep the old one) unless the track restarts.
    if (reset_evidence) {
      proxy_T_rival_.reset();
      rival_evidence_ = 0.0;
    }
    return;
  }
  // Evidence against one twin says nothing about another.
  if (reset_evidence || !proxy_T_rival_ ||
      RotationAngle(proxy_T_rival_->rotation, proxy_T_rival->rotation) > std::numbers::pi / 4) {
    rival_evidence_ = 0.0;
  }
  proxy_T_rival_ = proxy_T_rival;
}

ProxyTracker::Candidate ProxyTracker::RefineOnFrame(const RgbdFrame& frame,
                                                    const Rigid3& camera_T_start) {
  // Refined on the detection's subsample, then scored on all of this frame's data (as the
  // tracked pose is).
  const size_t medium_scored = PrepareMediumData();
  const double skin = options_.verification.skin_distance;
  const IcpResult coarse =
      AlignPointToPlane(*model_, detection_scratch_, medium_scored, skin, camera_T_start.Inverse(),
                        search_icp_, sample_matches_);
  IcpOptions final_icp = search_icp_;
  final_icp.max_iterations = 2;
  final_icp.start_distance = final_icp.end_distance;
  final_icp.shrink_iterations = 0;
  return Verify(frame, AlignPointToPlane(*model_, data_, scored_, skin, coarse.proxy_T_camera,
                                         final_icp, sample_matches_));
}

// Weight of a frame in the slide check's recent score (an exponential average over about the last
// 1 / weight = 10 measured frames).
constexpr double kRecentScoreWeight = 0.1;

bool ProxyTracker::CheckSlide(const RgbdFrame& frame, Candidate* chosen) {
  const DetectionOptions& o = options_.detection;
  if (!o.slide_check || o.seed_shift <= 0 || !chosen->good) return false;
  const double score = chosen->Score();
  const std::optional<double> reference = recent_score_;
  recent_score_ = reference ? *reference + kRecentScoreWeight * (score - *reference) : score;
  if (o.slide_drop > 0 && (!reference || score >= *reference - o.slide_drop)) return false;
  const Rigid3 camera_T_proxy = chosen->icp.proxy_T_camera.Inverse();
  const Eigen::Vector3d up = camera_T_table_->rotation * Eigen::Vector3d::UnitZ();
  std::optional<Candidate> best;
  for (double sign : {-1.0, 1.0}) {
    const Candidate shifted = RefineOnFrame(
        frame,
        Rigid3(camera_T_proxy.rotation, camera_T_proxy.translation + sign * o.seed_shift * up));
    if (shifted.good && (!best || shifted.Score() > best->Score())) best = shifted;
  }
  if (!best || best->Score() <= chosen->Score() + o.switch_margin) return false;
  *chosen = *best;
  return true;
}

bool ProxyTracker::WeighRival(const RgbdFrame& frame, Candidate* chosen) {
  const DetectionOptions& o = options_.detection;
  if (o.rival_threshold <= 0 || !proxy_T_rival_ || !chosen->good) return false;
  const double pi = std::numbers::pi;
  const Rigid3 camera_T_proxy = chosen->icp.proxy_T_camera.Inverse();
  const Candidate rival = RefineOnFrame(frame, camera_T_proxy * *proxy_T_rival_);
  const Rigid3 camera_T_refined = rival.icp.proxy_T_camera.Inverse();
  // Slid back onto the tracked pose: no twin here (this frame says nothing).
  if (RotationAngle(camera_T_refined.rotation, camera_T_proxy.rotation) <= pi / 4) return false;
  const double difference = rival.good ? rival.Score() - chosen->Score() : -o.rival_drift;
  rival_evidence_ = std::max(0.0, rival_evidence_ + difference - o.rival_drift);
  if (!rival.good) return false;
  if (rival_evidence_ <= o.rival_threshold) {
    proxy_T_rival_ = camera_T_proxy.Inverse() * camera_T_refined;
    return false;
  }
  // The rival has explained the data better for long enough: it is the pose, the old one its
  // rival.
  proxy_T_rival_ = camera_T_refined.Inverse() * camera_T_proxy;
  rival_evidence_ = 0.0;
  *chosen = rival;
  return true;
}

TrackFrameResult ProxyTracker::Lose(TrackFrameResult result, const std::string& reason) {
  result.status = TrackStatus::kLost;
  result.reason = reason;
  // The pose to re-acquire from (DetectionOptions::reacquire_frames): the last measured one, kept
  // for reacquire_frames lost frames.
  if (options_.detection.reacquire_frames > 0 && motion_->last()) {
    reacquire_pose_ = motion_->last();
    reacquire_age_ = 0;
    reacquire_tracked_frames_ = tracked_frames_;
    reacquire_predicted_frames_ = predicted_frames_;
  } else if (reacquire_pose_ && ++reacquire_age_ >= options_.detection.reacquire_frames) {
    reacquire_pose_.reset();
  }
  motion_->Reset();
  predicted_frames_ = 0;
  tracked_frames_ = 0;
  recent_score_.reset();
  SetRival(std::nullopt, true);
  return result;
}

std::string ProxyTracker::FrameProblem(const RgbdFrame& frame) const {
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  if (frame.depth.size() != static_cast<size_t>(k.width) * k.height || k.width <= 0 ||
      k.height <= 0) {
    return "depth has " + std::to_string(frame.depth.size()) + " pixels, expected " +
           std::to_string(k.width) + "x" + std::to_string(k.height) + " (its intrinsics)";
  }
  if (!(frame.depth_scale > 0) || !std::isfinite(frame.depth_scale)) {
    return "depth_scale " + FormatNumber(frame.depth_scale) + " is not a positive number";
  }
  if (intrinsics_ && !(*intrinsics_ == k)) {
    return "frame size or intrinsics differ from the first frame's (" + std::to_string(k.width) +
           "x" + std::to_string(k.height) + " vs " + std::to_string(intrinsics_->width) + "x" +
           std::to_string(intrinsics_->height) + ")";
  }
  if (!intrinsics_) {
    try {
      k.Validate("frame intrinsics");
    } catch (const InputError& e) {
      return e.what();
    }
  }
  if (std::none_of(frame.depth.begin(), frame.depth.end(), [](uint16_t d) { return d != 0; })) {
    return "depth all missing";
  }
  return "";
}

void ProxyTracker::KeepOwnSegments(const Rigid3& camera_T_proxy) {
  const DetectionOptions& o = options_.detection;
  const Eigen::Matrix3f r = camera_T_proxy.rotation.toRotationMatrix().cast<float>().transpose();
  const Eigen::Vector3f t = camera_T_proxy.translation.cast<float>();
  const float max_squared = static_cast<float>(o.own_segment_distance * o.own_segment_distance);
  const size_t count = segmentation_.component_sizes.size();
  std::vector<int> near(count, 0), total(count, 0);
  for (size_t i = 0; i < segmentation_.points.size(); ++i) {
    const int c = segmentation_.components[i];
    ++total[c];
    // The grid's nearest sample (track/proxy_model.h; within its margin, else none): the distance
    // to the surface up to the sample spacing, enough to tell the object from what lies beside it.
    const Eigen::Vector3f model_p = r * (segmentation_.points[i] - t);
    const int s = model_->Closest(model_p);
    if (s >= 0 && (model_->points()[s] - model_p).squaredNorm() <= max_squared) ++near[c];
  }
  std::vector<int> renumbered(count, -1);
  std::vector<int> sizes;
  for (size_t c = 0; c < count; ++c) {
    if (total[c] > 0 && near[c] >= o.own_segment_share * total[c]) {
      renumbered[c] = static_cast<int>(sizes.size());
      sizes.push_back(segmentation_.component_sizes[c]);
    }
  }
  size_t kept = 0;
  const bool flagged = segmentation_.outline.size() == segmentation_.points.size();
  for (size_t i = 0; i < segmentation_.points.size(); ++i) {
    const int c = renumbered[segmentation_.components[i]];
    if (c < 0) continue;
    segmentation_.points[kept] = segmentation_.points[i];
    if (flagged) segmentation_.outline[kept] = segmentation_.outline[i];
    segmentation_.components[kept++] = c;
  }
  segmentation_.points.resize(kept);
  segmentation_.components.resize(kept);
  if (flagged) segmentation_.outline.resize(kept);
  segmentation_.component_sizes = std::move(sizes);
}

void ProxyTracker::SegmentFrame(const RgbdFrame& frame, const ImageRect* window,
                                TrackFrameResult* result, const Rigid3* own) {
  segmenter_.Segment(frame, &segmentation_, window);
  if (own && options_.detection.own_segment_share > 0) KeepOwnSegments(*own);
  result->points = static_cast<int>(segmentation_.points.size());
  result->skin_points = static_cast<int>(segmentation_.skin_points.size());
  PrepareData();
}

std::optional<ProxyTracker::Candidate> ProxyTracker::TrackFromPrediction(
    const RgbdFrame& frame, const Rigid3& predicted, bool* windowed, TrackFrameResult* result,
    std::string* why) {
  const double pi = std::numbers::pi;
  std::optional<Candidate> chosen;
  const IcpResult icp =
      AlignPointToPlane(*model_, data_, scored_, options_.verification.skin_distance,
                        predicted.Inverse(), options_.icp, sample_matches_);
  Candidate candidate = Verify(frame, icp);
  if (candidate.good) {
    chosen = candidate;
  } else {
    *why = candidate.reason;
  }
  // A large correction of the prediction, or the periodic check, also asks the global detection
  // (a jump can land the ICP on a near-symmetric twin of the true pose, which verifies).
  const Rigid3 corrected = icp.proxy_T_camera.Inverse();
  const DetectionOptions& d = options_.detection;
  ++frames_since_detection_;
  const bool large_correction =
      RotationAngle(corrected.rotation, predicted.rotation) > d.recheck_rotation_deg * pi / 180 ||
      (corrected.translation - predicted.translation).norm() > d.recheck_translation;
  if (!chosen || !(large_correction || candidate.free_space_violation > d.recheck_free_space ||
                   (d.recheck_interval > 0 && frames_since_detection_ >= d.recheck_interval))) {
    return chosen;
  }
  frames_since_detection_ = 0;
  // A light check (periodic, or the free space growing) refines only the motion model's seeds and
  // the twins, all around the predicted proxy, so the window's data suffices; a large correction
  // searches the whole play area.
  const bool light = d.light_rechecks && !large_correction;
  if (*windowed && !light) {
    // Compare on the same data: the whole play area.
    *windowed = false;
    SegmentFrame(frame, nullptr, result);
    chosen = Verify(frame, AlignPointToPlane(*model_, data_, scored_,
                                             options_.verification.skin_distance,
                                             chosen->icp.proxy_T_camera, options_.icp,
                                             sample_matches_));
  }
  std::optional<Candidate> detected = Detect(frame, predicted, light);
  const bool far = detected && RotationAngle(detected->icp.proxy_T_camera.rotation,
                                             chosen->icp.proxy_T_camera.rotation) > pi / 4;
  // A trusted track leaves for a twin only on the twin evidence (WeighRival).
  const bool by_evidence = far && d.rival_threshold > 0 && tracked_frames_ >= d.trusted_frames;
  if (detected && detected->good &&
      (!chosen->good ||
       (!by_evidence &&
        detected->Score() > chosen->Score() + (far ? d.far_switch_margin : d.switch_margin)))) {
    chosen = detected;
    result->detected = true;
    SetRival(detection_rival_, far);
  } else if (!chosen->good) {
    *why = chosen->reason;
    chosen.reset();
  } else if (detected && detected->good && far) {
    // The tracked pose stays; the detection's pose is its rival.
    SetRival(chosen->icp.proxy_T_camera * detected->icp.proxy_T_camera.Inverse(), false);
  } else if (detected && detection_rival_) {
    // The detection agrees with the track: its rival, turned onto the tracked pose.
    SetRival(chosen->icp.proxy_T_camera * detected->icp.proxy_T_camera.Inverse() * *detection_rival_,
             false);
  }
  return chosen;
}

std::optional<ProxyTracker::Candidate> ProxyTracker::DetectAfterLoss(
    const RgbdFrame& frame, const std::optional<Rigid3>& predicted, TrackFrameResult* result,
    std::string* why, bool* held) {
  std::optional<Candidate> detected = options_.detection.model_segments > 0
                                          ? DetectAmongSegments(frame, predicted)
                                          : Detect(frame, predicted, false);
  frames_since_detection_ = 0;
  const double pi = std::numbers::pi;
  if (detected && detected->good && predicted && options_.detection.hold_trusted &&
      options_.detection.rival_threshold > 0 &&
      tracked_frames_ >= options_.detection.trusted_frames &&
      RotationAngle(detected->icp.proxy_T_camera.Inverse().rotation, predicted->rotation) >
          3 * pi / 4) {
    // A trusted track whose pose failed its verification does not leave for its half-turn twin on
    // the verification alone: the twin becomes the rival (its evidence decides, WeighRival) and
    // the frame is held (predicted). A pose less than 135 deg from the prediction may be a fast
    // turn the prediction missed (a Soldier turned by 40 deg in a few frames) and is taken.
    SetRival(predicted->Inverse() * detected->icp.proxy_T_camera.Inverse(), false);
    *held = true;
    *why = "only a twin of the trusted pose verified (held)";
    return std::nullopt;
  }
  if (detected && detected->good) {
    result->detected = true;
    // The twin evidence survives a detection that continues the track (the tracked pose failed
    // its verification on a frame, as under the hand it often does), unless it restarts it or
    // turns it onto a twin.
    SetRival(detection_rival_,
             !predicted || RotationAngle(detected->icp.proxy_T_camera.Inverse().rotation,
                                         predicted->rotation) > pi / 4);
    return detected;
  }
  if (why->empty()) {
    *why = detected ? "no pose hypothesis verified (best: " + detected->reason + ")"
                    : "no segment large enough for a detection";
  }
  return std::nullopt;
}

void ProxyTracker::ReportTracked(const RgbdFrame& frame, const Candidate& chosen, bool slid,
                                 TrackFrameResult* result) {
  // The reported pose is the projective refinement of the chosen one; the motion model, the
  // background and the checks keep the closest-point fit they were tuned on (refining that too
  // lost 0.3-0.6 points of frames within 5 deg and 1 cm on four Soldier takes and made a
  // 20-frame failure: docs/tracker.md).
  const Rigid3 camera_T_proxy = chosen.icp.proxy_T_camera.Inverse();
  Rigid3 camera_T_reported = camera_T_proxy;
  if (options_.projective.iterations > 0) {
    camera_T_reported =
        RefineProjective(*model_, *intrinsics_, data_, scored_, options_.verification.skin_distance,
                         chosen.icp.proxy_T_camera, options_.projective, sample_matches_)
            .Inverse();
  }
  // A pose moved by the slide check is a measurement, but no motion: the velocity restarts.
  motion_->Measure(camera_T_proxy, !result->detected && !slid);
  predicted_frames_ = 0;
  ++tracked_frames_;
  result->status = TrackStatus::kTracked;
  result->camera_T_proxy = camera_T_reported;
  result->inlier_share = chosen.icp.inlier_share;
  result->rms = chosen.icp.rms;
  result->free_space_violation = chosen.free_space_violation;
  result->iterations = chosen.icp.iterations;
  segmenter_.UpdateBackground(frame, ProxyImage(camera_T_proxy, 0.02));
}

TrackFrameResult ProxyTracker::Track(const RgbdFrame& frame) {
  TrackFrameResult result = TrackUnfiltered(frame);
  if (!options_.output_filter.enabled) return result;
  if (result.status == TrackStatus::kLost || result.detected) output_filter_.Reset();
  if (result.status != TrackStatus::kLost) {
    result.camera_T_proxy = output_filter_.Filter(result.timestamp, result.camera_T_proxy);
  }
  return result;
}

TrackFrameResult ProxyTracker::TrackUnfiltered(const RgbdFrame& frame) {
  TrackFrameResult result;
  result.index = frame.index;
  result.timestamp = frame.timestamp;
  // The frame itself, and the table (estimated once, on the first frame that has one).
  if (const std::string problem = FrameProblem(frame); !problem.empty()) {
    return Lose(result, problem);
  }
  std::string why;
  if (!EnsureTable(frame, &why)) return Lose(result, why);
  intrinsics_ = frame.depth_intrinsics;

  // With a prediction, only the predicted proxy's image is examined.
  const std::optional<Rigid3> predicted = motion_->Predict();
  ImageRect window;
  if (predicted) window = ProxyImage(*predicted, options_.segmentation.window_margin);
  SegmentFrame(frame, predicted ? &window : nullptr, &result, predicted ? &*predicted : nullptr);
  bool windowed = predicted.has_value();
  std::optional<Candidate> chosen;
  if (predicted && result.points >= options_.verification.min_points) {
    chosen = TrackFromPrediction(frame, *predicted, &windowed, &result, &why);
  }
  // Lost or none: the detection looks at the whole play area (a jump may have left the window).
  if (!chosen && windowed) SegmentFrame(frame, nullptr, &result);
  const bool enough = result.points >= options_.verification.min_points;
  bool held = false;
  if (!chosen && enough) {
    // After a loss, the pose before it seeds the detection and breaks its ties.
    // ... and continues the track's trust (DetectionOptions::reacquire_trust_frames) when the
    // whole gap, the frames predicted before the loss and the frames lost, is short enough.
    if (!predicted && reacquire_pose_ &&
        reacquire_predicted_frames_ + reacquire_age_ < options_.detection.reacquire_trust_frames) {
      tracked_frames_ = reacquire_tracked_frames_;
    }
    chosen = DetectAfterLoss(frame, predicted ? predicted : reacquire_pose_, &result, &why, &held);
  }
  if (chosen) {
    reacquire_pose_.reset();
    const bool slid = !result.detected && CheckSlide(frame, &*chosen);
    if (WeighRival(frame, &*chosen)) result.detected = true;
    ReportTracked(frame, *chosen, slid, &result);
    return result;
  }
  if (held && motion_->last() && predicted_frames_ < options_.verification.max_predicted_frames) {
    // Held: extrapolated as when hidden, but the track stays trusted and keeps its rival.
    ++predicted_frames_;
    result.status = TrackStatus::kPredicted;
    result.camera_T_proxy = motion_->Coast();
    result.reason = why;
    return result;
  }
  if (!enough) {
    why = "too few proxy points (" + std::to_string(result.points) + " < " +
          std::to_string(options_.verification.min_points) + ")";
    if (motion_->last() && predicted_frames_ < options_.verification.max_predicted_frames) {
      // Extrapolate, slowing down: a hidden proxy is more likely to stop than to fly on.
      const Rigid3 coasted = motion_->Coast();
      ++predicted_frames_;
      // Hidden for longer than reacquire_trust_frames, the proxy may be turned: continuity no
      // longer tells it from its twins.
      if (predicted_frames_ > options_.detection.reacquire_trust_frames) tracked_frames_ = 0;
      result.status = TrackStatus::kPredicted;
      result.camera_T_proxy = coasted;
      result.reason = why;
      return result;
    }
  }
  return Lose(result, why);
}

}  // namespace mmh::track
