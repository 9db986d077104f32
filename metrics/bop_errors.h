// The pose errors of the BOP benchmark (Hodan et al., "BOP Challenge 2020 on 6D Object
// Localization", ECCV workshops 2020, section 2.2; bop_toolkit's pose_error.py) and its
// average-recall summary, beside ADD and ADD-S (metrics/tracking_metrics.h):
//
//   MSSD = min over symmetries S of max over model points x of |est x - gt S x|      [m]
//   MSPD = min over S of max over x of |proj(est x) - proj(gt S x)|                 [px]
//   VSD  = per tolerance tau: (pixels of the visible union whose distance maps differ by tau or
//          more, or that only one pose covers) / (pixels of the visible union)   (BOP'19 visibility:
//          a rendered pixel is visible when the test image has no depth there or is not nearer
//          than delta)
//
// Symmetries are the object's symmetry transformations (BOP models_info.json, discretised as
// bop_toolkit does: metrics/model_symmetries.h); the identity is always one. VSD works on distance images (distance of
// the 3-D point from the camera centre, not its depth), as bop_toolkit does.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace mmh::metrics {

using ModelPoints = Eigen::Matrix<double, Eigen::Dynamic, 3>;

// The points the errors run over, as BOP's resampled models_eval: the mesh's distinct vertices
// (evenly subsampled to at most max_points, metrics/tracking_metrics.h MetricPoints) and, when
// they are fewer than `surface_points`, that many area-uniform surface points besides (a
// deterministic low-discrepancy sequence: a cuboid of 8 vertices is otherwise measured at its
// corners only).
ModelPoints ErrorPoints(const TriangleMesh& mesh, int surface_points = 1000, int max_points = 2000);

// Of camera_T_gt * object_T_symmetric over `symmetries` (and the identity), the pose MSSD measures
// camera_T_est against: the one nearest it by the largest point distance (the first on a tie).
Rigid3 NearestSymmetricTruth(const Rigid3& camera_T_est, const Rigid3& camera_T_gt,
                             const ModelPoints& points, const std::vector<Rigid3>& symmetries);

// MSSD [m] of camera_T_est against camera_T_gt over `points`, minimum over `symmetries`
// (object_T_symmetric; empty: the identity only).
double Mssd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt, const ModelPoints& points,
            const std::vector<Rigid3>& symmetries = {});

// MSPD [px] with the camera `intrinsics` (points behind the camera are projected as they are).
double Mspd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt, const ModelPoints& points,
            const PinholeIntrinsics& intrinsics, const std::vector<Rigid3>& symmetries = {});

// The distance image [m] (0: no surface) of `mesh` at camera_T_object: each pixel centre's ray
// meets the nearest triangle (z-buffer; triangles with a vertex closer than 1 mm to the camera
// plane are skipped).
std::vector<float> RenderDistance(const TriangleMesh& mesh, const Rigid3& camera_T_object,
                                  const PinholeIntrinsics& intrinsics);

// The test image's distance image [m] from its depth (depth units times depth_scale; 0 stays 0).
std::vector<float> DepthToDistance(const std::vector<uint16_t>& depth, double depth_scale,
                                   const PinholeIntrinsics& intrinsics);

// VSD per tolerance in `taus` [m] (BOP: taus = diameter * 0.05 ... 0.5), visibility tolerance
// delta [m] (BOP: 0.015); 1 for every tau when neither pose is visible.
std::vector<double> Vsd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt,
                        const TriangleMesh& mesh, const std::vector<float>& test_distance,
                        const PinholeIntrinsics& intrinsics, double delta,
                        const std::vector<double>& taus);

struct BopRecallOptions {
  // Thresholds as fractions of the diameter (MSSD, VSD's tau and its correctness threshold):
  // BOP 2019-2023, 0.05 to 0.5 in steps of 0.05.
  std::vector<double> diameter_fractions = {0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5};
  // MSPD thresholds [px] for a 640-pixel-wide image, scaled by width / 640: 5 to 50 in steps of 5.
  std::vector<double> mspd_pixels = {5, 10, 15, 20, 25, 30, 35, 40, 45, 50};
  // VSD's visibility tolerance [m] (BOP: 15 mm).
  double vsd_delta = 0.015;
  // ADD and ADD-S are correct below add_fraction of the diameter (Hinterstoisser et al. 2012).
  double add_fraction = 0.1;

  template <class Visitor>
  void VisitFields(Visitor& v) {
    // The threshold lists are BOP's and not configurable from JSON (options hold scalars).
    v("vsd_delta", vsd_delta);
    v("add_fraction", add_fraction);
  }
  void Validate(const std::string& prefix) const;
};

// The errors of one estimate (or of a missing one: every error infinite, never correct).
struct BopFrameErrors {
  bool has_estimate = false;
  double rotation_deg = 0.0;  // [deg]
  double translation = 0.0;   // [m]
  double add = 0.0, adds = 0.0, mssd = 0.0;  // [m]
  double mspd = 0.0;                         // [px]
  std::vector<double> vsd;                   // per tau (empty: no depth image)
};

struct BopRecall {
  int frames = 0;
  double ar_vsd = 0.0, ar_mssd = 0.0, ar_mspd = 0.0;
  // BOP's AR: the mean of the three (of AR_MSSD and AR_MSPD when no frame has VSD).
  double ar = 0.0;
  double add_recall = 0.0, adds_recall = 0.0;
  double recall_5deg_5cm = 0.0, recall_2deg_2cm = 0.0;
  double median_rotation_deg = 0.0, median_translation = 0.0;  // over frames with an estimate
  bool has_vsd = false;
};

// Recall over frames (a missing estimate counts as incorrect), each AR the mean recall over its
// thresholds (VSD: over every tau and correctness threshold pair).
BopRecall SummarizeBop(const std::vector<BopFrameErrors>& frames, double diameter, int image_width,
                       const BopRecallOptions& options);

nlohmann::json ToJson(const BopRecall& recall);

}  // namespace mmh::metrics
