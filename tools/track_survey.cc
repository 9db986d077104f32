// A survey of the proxy tracker on simulated story recordings (a research tool, not a test):
// tracks the given stretches of takes and prints every failed frame with the score of the true
// pose refined on the same data (is a failure the tracker's search or the data's minimum?), and
// with --crb the Cramer-Rao bound of the rotation and fits from ideal correspondences.
//
//   build/tools/track_survey [--config configs/mario.json] [--set tracker.x=v ...] [--crb] [--all] [--brief]
//                            animator:take:first:frames ...      (default 3:1:0:300)
//
// docs/tracker.md reports what it found.
#include <unistd.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "metrics/tracking_metrics.h"
#include "tests/track/sim_take.h"
#include "track/proxy_tracker.h"

namespace mmh::track {
namespace {

struct SurveyArgs {
  std::string config = "configs/study_soldier.json";  // relative to the project's folder
  std::vector<std::string> sets;
  bool crb = false;
  bool all = false;
  bool brief = false;  // failed frames in one line each
  std::vector<std::string> stretches;
};

SurveyArgs ParseArgs(int argc, char** argv) {
  SurveyArgs args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--config" && i + 1 < argc) {
      args.config = argv[++i];
    } else if (a == "--set" && i + 1 < argc) {
      args.sets.push_back(argv[++i]);
    } else if (a == "--crb") {
      args.crb = true;
    } else if (a == "--all") {
      args.all = true;
    } else if (a == "--brief") {
      args.brief = true;
    } else if (!a.empty() && a[0] != '-' && std::count(a.begin(), a.end(), ':') == 3) {
      args.stretches.push_back(a);
    } else {
      throw InputError("track_survey: unknown argument '" + a +
                       "' (expected --config FILE, --set key=value, --crb, --all, --brief or "
                       "animator:take:first:frames)");
    }
  }
  if (args.stretches.empty()) args.stretches.push_back("3:1:0:300");
  return args;
}

// One stretch of a take: "animator:take:first:frames".
struct Stretch {
  int animator = 0, take = 0, first = 0, frames = 0;
};

Stretch ParseStretch(const std::string& item) {
  Stretch s;
  std::sscanf(item.c_str(), "%d:%d:%d:%d", &s.animator, &s.take, &s.first, &s.frames);
  return s;
}

// The same take without noise and lattice: each pixel's true surface point.
std::unique_ptr<test_take::SimTake> CleanTake(const SurveyArgs& args, const Stretch& stretch) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mmh_track_survey_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  nlohmann::json clean_json =
      nlohmann::json::parse(std::ifstream(std::string(MMH_SOURCE_DIR) + "/" + args.config));
  clean_json["sensor"]["noise"] = false;
  clean_json["sensor"]["quantise"] = false;
  const std::filesystem::path clean_file = dir / "clean.json";
  std::ofstream(clean_file) << clean_json.dump();
  int unused = 0;
  return std::make_unique<test_take::SimTake>(test_take::SoldierStorySession(
      MMH_SOURCE_DIR, stretch.animator, stretch.take, sim::RenderSession::kRecording, &unused,
      std::filesystem::relative(clean_file, MMH_SOURCE_DIR).string()));
}

// A depth's standard deviation: the sensor's axial noise and the lattice's step^2 / 12.
double DepthSigma(const sim::KinectSensorOptions& sensor, double z, double theta) {
  const double step = z * z /
                      (sensor.calibration.subpixel_steps * sensor.calibration.ir_focal_length *
                       sensor.calibration.baseline);
  return std::hypot(sensor.axial.Sigma(z, theta), step / std::sqrt(12.0));
}

// Cramer-Rao bound of the rotation from this frame's segmented points at the true pose: each
// point's point-to-plane residual has its depth's sigma times |n . ray|. Returns the covariance of
// the rotation (3 x 3, rad^2).
Eigen::Matrix3d RotationCrb(const ProxyTracker& tracker, const sim::KinectSensorOptions& sensor,
                            const Rigid3& truth, int* used) {
  const Rigid3 proxy_T_camera = truth.Inverse();
  Eigen::Matrix<double, 6, 6> fisher = Eigen::Matrix<double, 6, 6>::Zero();
  *used = 0;
  for (const Eigen::Vector3f& pf : tracker.last_segmentation().points) {
    const Eigen::Vector3d p = pf.cast<double>();
    const Eigen::Vector3d q = proxy_T_camera * p;
    const int s = tracker.model().Closest(q.cast<float>());
    if (s < 0) continue;
    const Eigen::Vector3d n_model = tracker.model().normals()[s].cast<double>();
    if (std::abs(n_model.dot(q - tracker.model().points()[s].cast<double>())) > 0.004) continue;
    const Eigen::Vector3d n = truth.rotation * n_model;
    const double cos_incidence = std::min(1.0, std::abs(n.dot(p.normalized())));
    const double sigma =
        DepthSigma(sensor, p.z(), std::acos(cos_incidence)) * std::max(cos_incidence, 0.05);
    Eigen::Matrix<double, 6, 1> g;
    g << p.cross(n), n;
    fisher += g * g.transpose() / (sigma * sigma);
    ++*used;
  }
  return fisher.inverse().topLeftCorner<3, 3>();
}

// The fit with ideal correspondences: each point's pixel on the noise-free frame (the surface
// point it measures) with that point's model normal; IRLS (Huber 3 mm) on n . (R p + t - p0),
// unweighted (ml false) and with the ML weights 1 / sigma^2. Returns the rotation error [deg] of
// each.
std::array<double, 2> IdealFits(const ProxyTracker& tracker, const sim::KinectSensorOptions& sensor,
                                const RgbdFrame& clean_frame, const Rigid3& truth) {
  const Rigid3 proxy_T_camera = truth.Inverse();
  const auto& in = clean_frame.depth_intrinsics;
  std::vector<Eigen::Vector3d> ps, p0s, ns;
  std::vector<double> sig;
  for (const Eigen::Vector3f& pf : tracker.last_segmentation().points) {
    const Eigen::Vector3d p = pf.cast<double>();
    const int u = static_cast<int>(std::lround(in.fx * p.x() / p.z() + in.cx));
    const int v = static_cast<int>(std::lround(in.fy * p.y() / p.z() + in.cy));
    if (u < 0 || v < 0 || u >= in.width || v >= in.height) continue;
    const double z0 = clean_frame.DepthMetres(u, v);
    if (z0 <= 0) continue;
    const Eigen::Vector3d p0((u - in.cx) * z0 / in.fx, (v - in.cy) * z0 / in.fy, z0);
    const Eigen::Vector3d q0 = proxy_T_camera * p0;
    const int s0 = tracker.model().Closest(q0.cast<float>());
    if (s0 < 0) continue;
    if ((q0 - tracker.model().points()[s0].cast<double>()).norm() > 0.003) continue;
    const Eigen::Vector3d n = truth.rotation * tracker.model().normals()[s0].cast<double>();
    const double c = std::abs(n.dot(p0.normalized()));
    ps.push_back(p);
    p0s.push_back(p0);
    ns.push_back(n);
    sig.push_back(DepthSigma(sensor, z0, std::acos(std::min(c, 1.0))) * std::max(c, 0.05));
  }
  std::array<double, 2> fits{};
  for (int ml = 0; ml < 2; ++ml) {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (int it = 0; it < 6; ++it) {
      Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      for (size_t k = 0; k < ps.size(); ++k) {
        const Eigen::Vector3d x = R * ps[k] + t;
        const double r = ns[k].dot(x - p0s[k]);
        const double scale = ml ? sig[k] : 0.003;
        const double huber = ml ? 1.5 * sig[k] : 0.003;
        double w = std::abs(r) <= huber ? 1.0 : huber / std::abs(r);
        w /= scale * scale;
        Eigen::Matrix<double, 6, 1> g;
        g << x.cross(ns[k]), ns[k];
        H += w * g * g.transpose();
        b -= w * g * r;
      }
      const Eigen::Matrix<double, 6, 1> d = H.ldlt().solve(b);
      const Eigen::Vector3d w3 = d.head<3>();
      const Eigen::Matrix3d dR = w3.norm() > 0
                                     ? Eigen::AngleAxisd(w3.norm(), w3.normalized()).toRotationMatrix()
                                     : Eigen::Matrix3d::Identity();
      R = dR * R;
      t = dR * t + d.tail<3>();
    }
    fits[ml] = Eigen::AngleAxisd(R).angle() * 180 / M_PI;
  }
  return fits;
}

// --all: every frame's truth (table frame) and the estimate's rotation and shift against it.
void PrintFrame(const test_take::SimTake& take, int i, const Rigid3& truth,
                const TrackFrameResult& r, double rot) {
  const Rigid3 table_T_truth = take.depth_T_table().Inverse() * truth;
  const Rigid3 table_T_estimate = take.depth_T_table().Inverse() * r.camera_T_proxy;
  const Eigen::AngleAxisd e(table_T_estimate.rotation * table_T_truth.rotation.inverse());
  const Eigen::Vector3d v = e.angle() * 180 / M_PI * e.axis();
  const Eigen::Vector3d x = table_T_truth.rotation * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d shift = 1000 * (table_T_estimate.translation - table_T_truth.translation);
  std::printf("truth %.3f %.3f %.3f ", table_T_truth.translation.x(), table_T_truth.translation.y(),
              table_T_truth.translation.z());
  std::printf("all %d rot %.2f axis %.2f %.2f %.2f shift %.1f %.1f %.1f xdir %.2f %.2f\n", i, rot,
              v.x(), v.y(), v.z(), shift.x(), shift.y(), shift.z(), x.x(), x.y());
}

// A failed frame in full: the error's axis and shift in the table frame, the basin of the truth
// (ICP from the truth turned by 3 deg about each table axis, both ways), and the scores of the
// estimate and of the truth refined on the same data.
void PrintFailure(const test_take::SimTake& take, ProxyTracker& tracker, const RgbdFrame& frame,
                  int i, const Rigid3& truth, const TrackFrameResult& r, double rot,
                  double trans) {
  const Rigid3 table_T_proxy = take.depth_T_table().Inverse() * truth;
  const double tilt = std::acos(std::clamp((table_T_proxy.rotation * Eigen::Vector3d::UnitZ()).z(),
                                           -1.0, 1.0)) *
                      180 / M_PI;
  const Rigid3 table_T_estimate = take.depth_T_table().Inverse() * r.camera_T_proxy;
  const Eigen::AngleAxisd error_rotation(table_T_estimate.rotation *
                                         table_T_proxy.rotation.inverse());
  const Eigen::Vector3d axis = error_rotation.axis();
  const Eigen::Vector3d shift = table_T_estimate.translation - table_T_proxy.translation;
  std::printf("  axis %.2f %.2f %.2f shift %.1f %.1f %.1f mm; proxy x axis in table %.2f %.2f\n",
              axis.x(), axis.y(), axis.z(), shift.x() * 1000, shift.y() * 1000, shift.z() * 1000,
              (table_T_proxy.rotation * Eigen::Vector3d::UnitX()).x(),
              (table_T_proxy.rotation * Eigen::Vector3d::UnitX()).y());
  const auto at_truth = tracker.ScorePose(frame, truth);
  const auto at_estimate = tracker.ScorePose(frame, r.camera_T_proxy);
  std::string basin;
  for (int table_axis = 0; table_axis < 3; ++table_axis) {
    for (double angle : {-3.0, 3.0}) {
      const Eigen::Quaterniond turn(Eigen::AngleAxisd(
          angle * M_PI / 180, take.depth_T_table().rotation * Eigen::Vector3d::Unit(table_axis)));
      const Rigid3 start(turn * truth.rotation, truth.translation);
      const auto from = tracker.ScorePose(frame, start);
      char text[64];
      std::snprintf(text, sizeof(text), " %.1f/%.2f",
                    RotationAngle(from.camera_T_proxy.rotation, truth.rotation) * 180 / M_PI,
                    from.score);
      basin += text;
    }
  }
  std::printf("  basin%s\n", basin.c_str());
  std::printf(
      "frame %d %s det %d rot %.1f tr %.1fmm | pts %d skin %d | tilt %.0f z %.0fmm | est: "
      "score %.3f share %.2f fs %.3f | truth->%.1fdeg %.1fmm score %.3f share %.2f fs %.3f "
      "good %d %s\n",
      i, TrackStatusName(r.status), r.detected, rot, trans * 1000, r.points, r.skin_points, tilt,
      table_T_proxy.translation.z() * 1000, at_estimate.score, at_estimate.inlier_share,
      at_estimate.free_space_violation,
      RotationAngle(at_truth.camera_T_proxy.rotation, truth.rotation) * 180 / M_PI,
      (at_truth.camera_T_proxy.translation - truth.translation).norm() * 1000, at_truth.score,
      at_truth.inlier_share, at_truth.free_space_violation, at_truth.good, r.reason.c_str());
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// The --crb figures of a stretch: draws of the rotation error under the bound, the fit from the
// truth, and the two fits with ideal correspondences.
struct CrbFigures {
  std::vector<double> draws, truth_fit, ideal_fit[2];
};

void SurveyStretch(const SurveyArgs& args, const std::string& item) {
  Stretch stretch = ParseStretch(item);
  int take_frames = 0;
  test_take::SimTake take = test_take::SoldierStorySession(
      MMH_SOURCE_DIR, stretch.animator, stretch.take, sim::RenderSession::kRecording, &take_frames,
      args.config);
  const int first = stretch.first;
  const int frames = std::min(stretch.frames, take_frames - first);
  std::printf("== animator %d take %d frames %d..%d of %d\n", stretch.animator, stretch.take, first,
              first + frames, take_frames);
  Config config;
  for (const std::string& set : args.sets) config.Set(set);
  ProxyTracker tracker(take.model(), "soldier", take.Setup(),
                       config.Get<ProxyTrackerOptions>("tracker"));
  const std::unique_ptr<test_take::SimTake> clean = args.crb ? CleanTake(args, stretch) : nullptr;
  int ok = 0;
  CrbFigures crb;
  std::vector<std::optional<Rigid3>> estimates;
  std::vector<Rigid3> truths;
  for (int i = first; i < first + frames; ++i) {
    Rigid3 truth;
    const RgbdFrame frame = take.Render(i, &truth);
    const TrackFrameResult r = tracker.Track(frame);
    truths.push_back(truth);
    estimates.push_back(r.status != TrackStatus::kLost ? std::optional(r.camera_T_proxy)
                                                       : std::nullopt);
    const double rot = RotationAngle(r.camera_T_proxy.rotation, truth.rotation) * 180 / M_PI;
    const double trans = (r.camera_T_proxy.translation - truth.translation).norm();
    const bool success = r.status != TrackStatus::kLost && rot < 5 && trans < 0.01;
    ok += success;
    if (args.all) PrintFrame(take, i, truth, r, rot);
    if (args.crb) {
      const auto& sensor = take.config().sensor;
      int used = 0;
      const Eigen::Matrix3d cov = RotationCrb(tracker, sensor, truth, &used);
      const Eigen::Matrix3d chol = cov.llt().matrixL();
      static std::mt19937_64 random(1);
      std::normal_distribution<double> normal;
      for (int k = 0; k < 64; ++k) {
        const Eigen::Vector3d w(normal(random), normal(random), normal(random));
        crb.draws.push_back((chol * w).norm() * 180 / M_PI);
      }
      const std::array<double, 2> fits = IdealFits(tracker, sensor, clean->Render(i), truth);
      for (int ml = 0; ml < 2; ++ml) crb.ideal_fit[ml].push_back(fits[ml]);
      const auto from_truth = tracker.ScorePose(frame, truth);
      crb.truth_fit.push_back(RotationAngle(from_truth.camera_T_proxy.rotation, truth.rotation) *
                              180 / M_PI);
      if (args.all) {
        std::printf("crb %d used %d rms %.2f deg\n", i, used, std::sqrt(cov.trace()) * 180 / M_PI);
      }
    }
    if (success) continue;
    if (args.brief) {
      std::printf("frame %d %s det %d rot %.1f tr %.1fmm pts %d skin %d %s\n", i,
                  TrackStatusName(r.status), r.detected, rot, trans * 1000, r.points, r.skin_points,
                  r.reason.c_str());
      continue;
    }
    PrintFailure(take, tracker, frame, i, truth, r, rot, trans);
  }
  std::printf("== success %.4f (%d of %d)\n", static_cast<double>(ok) / frames, ok, frames);
  if (!crb.draws.empty()) {
    std::printf("== crb median rotation %.3f deg\n", Median(crb.draws));
    std::printf("== fit from the truth: median rotation %.3f deg\n", Median(crb.truth_fit));
    for (const auto& f : crb.ideal_fit) {
      std::printf("== ideal correspondences: median rotation %.3f deg\n", Median(f));
    }
  }
  const auto points = metrics::MetricPoints(take.model());
  const metrics::PoseErrorOptions metric_options;
  const metrics::TrackingSummary summary = metrics::SummarizeTracking(
      metrics::ComputePoseErrors(estimates, truths, points, metric_options),
      metrics::Diameter(points), metric_options);
  std::printf("== summary %d:%d success %.4f median %.2f deg %.2f mm longest %d recovered %d\n",
              stretch.animator, stretch.take, summary.success_rate, summary.median_rotation_deg,
              summary.median_translation * 1000, summary.longest_failure, summary.all_recovered);
}

void Survey(const SurveyArgs& args) {
  for (const std::string& item : args.stretches) SurveyStretch(args, item);
}

}  // namespace
}  // namespace mmh::track

int main(int argc, char** argv) {
  try {
    mmh::track::Survey(mmh::track::ParseArgs(argc, argv));
  } catch (const mmh::InputError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
