// `mmh eval`'s work: a tracked object's poses against a recording's ground truth, frame by frame,
// with every error of metrics/bop_errors.h and metrics/tracking_metrics.h, summarised per object
// as BOP's average recall and the 5 deg / 5 cm and 2 deg / 2 cm recalls; written as tidy CSV
// (one row per object and frame; one row per object) and JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "metrics/bop_errors.h"

namespace mmh::metrics {

struct PoseEvaluationOptions {
  // Area-uniform surface points added to a model with fewer vertices (ErrorPoints).
  int surface_points = 1000;
  // VSD needs the test depth image and two renderings per frame; false: MSSD and MSPD only.
  bool vsd = true;
  // Ground-truth instances less visible than this (BOP scene_gt_info.json's visib_fract) are left
  // out, as BOP's score calculation does (bop_toolkit eval_calc_scores, visib_gt_min 0.1); frames
  // whose visibility the dataset does not give are kept.
  double min_visible_fraction = 0.1;
  // bop_toolkit's discretisation of continuous symmetries (metrics/model_symmetries.h).
  double max_symmetry_step = 0.01;
  BopRecallOptions bop;

  template <class V>
  void VisitFields(V& v) {
    v("surface_points", surface_points);
    v("vsd", vsd);
    v("min_visible_fraction", min_visible_fraction);
    v("max_symmetry_step", max_symmetry_step);
    v("bop", bop);
  }
  void Validate(const std::string& prefix) const;
};

struct EvaluationFrame {
  int frame = 0;          // index in the recording
  double timestamp = 0.0;  // [s]
  Rigid3 camera_T_truth;
  std::optional<Rigid3> camera_T_estimate;  // nullopt: no estimate (lost)
  PinholeIntrinsics intrinsics;
  // The instance's visible share (BOP visib_fract; -1: not given).
  double visible_fraction = -1.0;
  // The test image's distance image (DepthToDistance); empty: no VSD for this frame.
  std::vector<float> test_distance;
};

struct ObjectEvaluation {
  int object = 0;
  double diameter = 0.0;  // [m], over the error points
  int points = 0;         // error points
  int symmetries = 0;     // symmetry transformations besides the identity
  int low_visibility = 0;  // frames left out (visible_fraction < min_visible_fraction)
  std::vector<EvaluationFrame> frames;  // without the distance images
  std::vector<BopFrameErrors> errors;   // per frame
  BopRecall recall;
};

// Errors of every frame and their summary. `symmetries`: object_T_symmetric (SymmetryTransformations;
// the identity is implied): MSSD and MSPD take the minimum over them, and the rotation and
// translation errors (and the 5 deg / 5 cm, 2 deg / 2 cm recalls) are measured against the
// symmetric truth MSSD picks (NearestSymmetricTruth); ADD stays against the truth itself, ADD-S
// needs none.
ObjectEvaluation EvaluateObject(int object, std::vector<EvaluationFrame> frames,
                                const TriangleMesh& model, const std::vector<Rigid3>& symmetries,
                                const PoseEvaluationOptions& options);

// Tidy tables: object,frame,timestamp,has_estimate,rotation_deg,translation_mm,add_mm,adds_mm,
// mssd_mm,mspd_px,vsd_mean (empty without VSD), one row per object and frame; and
// object,frames,diameter_mm,ar,ar_vsd,ar_mssd,ar_mspd,add_recall,adds_recall,recall_5deg_5cm,
// recall_2deg_2cm,median_rotation_deg,median_translation_mm, one row per object.
std::string FramesCsv(const std::vector<ObjectEvaluation>& objects);
std::string ObjectsCsv(const std::vector<ObjectEvaluation>& objects);

// The objects' instances pooled, as BOP's dataset score pools them: every recall and AR the
// frame-weighted mean of the objects' (a recall is correct instances over instances, so the
// weighted mean is the pooled count), the medians over every frame with an estimate.
BopRecall PooledRecall(const std::vector<ObjectEvaluation>& objects);
// One row: objects,frames,ar,ar_vsd,ar_mssd,ar_mspd,add_recall,adds_recall,recall_5deg_5cm,
// recall_2deg_2cm,median_rotation_deg,median_translation_mm.
std::string OverallCsv(const std::vector<ObjectEvaluation>& objects);
nlohmann::json ToJson(const ObjectEvaluation& evaluation);

}  // namespace mmh::metrics
