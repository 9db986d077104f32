#include "metrics/pose_evaluation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/error.h"
#include "metrics/tracking_metrics.h"

namespace mmh::metrics {

void PoseEvaluationOptions::Validate(const std::string& prefix) const {
  if (surface_points < 0) {
    ThrowBadValue(prefix + ".surface_points", std::to_string(surface_points), ">= 0");
  }
  RequireProbability(min_visible_fraction, prefix + ".min_visible_fraction");
  RequirePositive(max_symmetry_step, prefix + ".max_symmetry_step");
  bop.Validate(prefix + ".bop");
}

ObjectEvaluation EvaluateObject(int object, std::vector<EvaluationFrame> frames,
                                const TriangleMesh& model, const std::vector<Rigid3>& symmetries,
                                const PoseEvaluationOptions& options) {
  options.Validate("eval");
  ObjectEvaluation evaluation;
  evaluation.object = object;
  evaluation.symmetries = static_cast<int>(symmetries.size());
  const size_t all_frames = frames.size();
  std::erase_if(frames, [&](const EvaluationFrame& f) {
    return f.visible_fraction >= 0 && f.visible_fraction < options.min_visible_fraction;
  });
  evaluation.low_visibility = static_cast<int>(all_frames - frames.size());
  const ModelPoints points = ErrorPoints(model, options.surface_points);
  evaluation.points = static_cast<int>(points.rows());
  evaluation.diameter = Diameter(points);
  std::vector<std::optional<Rigid3>> estimates;
  std::vector<Rigid3> truths;
  for (const auto& f : frames) {
    estimates.push_back(f.camera_T_estimate);
    truths.push_back(f.camera_T_truth);
  }
  PoseErrorOptions pose_options;
  pose_options.add_fraction = options.bop.add_fraction;
  const std::vector<FramePoseError> basic = ComputePoseErrors(estimates, truths, points, pose_options);
  std::vector<double> taus;
  for (double f : options.bop.diameter_fractions) taus.push_back(f * evaluation.diameter);
  for (size_t i = 0; i < frames.size(); ++i) {
    EvaluationFrame& f = frames[i];
    BopFrameErrors e;
    e.has_estimate = f.camera_T_estimate.has_value();
    if (e.has_estimate) {
      const Rigid3 truth =
          NearestSymmetricTruth(*f.camera_T_estimate, f.camera_T_truth, points, symmetries);
      e.rotation_deg =
          RotationAngle(f.camera_T_estimate->rotation, truth.rotation) * 180 / std::numbers::pi;
      e.translation = (f.camera_T_estimate->translation - truth.translation).norm();
      e.add = basic[i].add;
      e.adds = basic[i].adds;
      e.mssd = Mssd(*f.camera_T_estimate, f.camera_T_truth, points, symmetries);
      e.mspd = Mspd(*f.camera_T_estimate, f.camera_T_truth, points, f.intrinsics, symmetries);
      if (options.vsd && !f.test_distance.empty()) {
        e.vsd = Vsd(*f.camera_T_estimate, f.camera_T_truth, model, f.test_distance, f.intrinsics,
                    options.bop.vsd_delta, taus);
      }
    }
    f.test_distance.clear();
    f.test_distance.shrink_to_fit();
    evaluation.errors.push_back(e);
  }
  const int width = frames.empty() ? 640 : frames.front().intrinsics.width;
  evaluation.recall = SummarizeBop(evaluation.errors, evaluation.diameter, width, options.bop);
  evaluation.frames = std::move(frames);
  return evaluation;
}

namespace {
std::string Number(double value) { return FormatNumber(std::round(value * 1e6) / 1e6); }
}  // namespace

std::string FramesCsv(const std::vector<ObjectEvaluation>& objects) {
  std::ostringstream out;
  out << "object,frame,timestamp,has_estimate,rotation_deg,translation_mm,add_mm,adds_mm,mssd_mm,"
         "mspd_px,vsd_mean\n";
  for (const auto& o : objects) {
    for (size_t i = 0; i < o.frames.size(); ++i) {
      const BopFrameErrors& e = o.errors[i];
      out << o.object << ',' << o.frames[i].frame << ',' << Number(o.frames[i].timestamp) << ','
          << (e.has_estimate ? 1 : 0) << ',';
      if (!e.has_estimate) {
        out << ",,,,,,\n";
        continue;
      }
      double vsd = 0;
      for (double v : e.vsd) vsd += v;
      out << Number(e.rotation_deg) << ',' << Number(e.translation * 1000) << ','
          << Number(e.add * 1000) << ',' << Number(e.adds * 1000) << ','
          << Number(e.mssd * 1000) << ',' << Number(e.mspd) << ','
          << (e.vsd.empty() ? "" : Number(vsd / e.vsd.size())) << '\n';
    }
  }
  return out.str();
}

namespace {

// ar,ar_vsd,ar_mssd,ar_mspd,add_recall,adds_recall,recall_5deg_5cm,recall_2deg_2cm,
// median_rotation_deg,median_translation_mm
std::string RecallColumns(const BopRecall& r) {
  return Number(r.ar) + ',' + (r.has_vsd ? Number(r.ar_vsd) : "") + ',' + Number(r.ar_mssd) + ',' +
         Number(r.ar_mspd) + ',' + Number(r.add_recall) + ',' + Number(r.adds_recall) + ',' +
         Number(r.recall_5deg_5cm) + ',' + Number(r.recall_2deg_2cm) + ',' +
         Number(r.median_rotation_deg) + ',' + Number(r.median_translation * 1000);
}

constexpr char kRecallHeader[] =
    "ar,ar_vsd,ar_mssd,ar_mspd,add_recall,adds_recall,recall_5deg_5cm,recall_2deg_2cm,"
    "median_rotation_deg,median_translation_mm";

}  // namespace

std::string ObjectsCsv(const std::vector<ObjectEvaluation>& objects) {
  std::ostringstream out;
  out << "object,frames,diameter_mm," << kRecallHeader << '\n';
  for (const auto& o : objects) {
    out << o.object << ',' << o.recall.frames << ',' << Number(o.diameter * 1000) << ','
        << RecallColumns(o.recall) << '\n';
  }
  return out.str();
}

BopRecall PooledRecall(const std::vector<ObjectEvaluation>& objects) {
  BopRecall pooled;
  int vsd_frames = 0;
  std::vector<double> rotations, translations;
  for (const auto& o : objects) {
    const BopRecall& r = o.recall;
    pooled.frames += r.frames;
    pooled.ar += r.frames * r.ar;
    pooled.ar_mssd += r.frames * r.ar_mssd;
    pooled.ar_mspd += r.frames * r.ar_mspd;
    pooled.add_recall += r.frames * r.add_recall;
    pooled.adds_recall += r.frames * r.adds_recall;
    pooled.recall_5deg_5cm += r.frames * r.recall_5deg_5cm;
    pooled.recall_2deg_2cm += r.frames * r.recall_2deg_2cm;
    if (r.has_vsd) {
      pooled.has_vsd = true;
      pooled.ar_vsd += r.frames * r.ar_vsd;
      vsd_frames += r.frames;
    }
    for (const BopFrameErrors& e : o.errors) {
      if (!e.has_estimate) continue;
      rotations.push_back(e.rotation_deg);
      translations.push_back(e.translation);
    }
  }
  if (pooled.frames > 0) {
    for (double* v : {&pooled.ar, &pooled.ar_mssd, &pooled.ar_mspd, &pooled.add_recall,
                      &pooled.adds_recall, &pooled.recall_5deg_5cm, &pooled.recall_2deg_2cm}) {
      *v /= pooled.frames;
    }
  }
  if (vsd_frames > 0) pooled.ar_vsd /= vsd_frames;
  pooled.median_rotation_deg = Quantile(rotations, 0.5);
  pooled.median_translation = Quantile(translations, 0.5);
  return pooled;
}

std::string OverallCsv(const std::vector<ObjectEvaluation>& objects) {
  const BopRecall r = PooledRecall(objects);
  return std::string("objects,frames,") + kRecallHeader + '\n' + std::to_string(objects.size()) +
         ',' + std::to_string(r.frames) + ',' + RecallColumns(r) + '\n';
}

nlohmann::json ToJson(const ObjectEvaluation& evaluation) {
  nlohmann::json j = ToJson(evaluation.recall);
  j["object"] = evaluation.object;
  j["diameter_mm"] = evaluation.diameter * 1000;
  j["error_points"] = evaluation.points;
  j["symmetries"] = evaluation.symmetries;
  j["low_visibility_frames_left_out"] = evaluation.low_visibility;
  return j;
}

}  // namespace mmh::metrics
