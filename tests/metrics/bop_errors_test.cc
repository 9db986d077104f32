// BOP pose errors against hand-computed values and brute force: MSSD and MSPD on squares whose
// answers follow from geometry, the z-buffer renderer against ray casting (Moller-Trumbore) of
// every pixel, VSD on planes filling the image, and the average recall on a two-frame case
// counted by hand.
#include "metrics/bop_errors.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "metrics/tracking_metrics.h"
#include "tests/test_meshes.h"

namespace mmh::metrics {
namespace {

ModelPoints Square(double a) {
  ModelPoints p(4, 3);
  p << a, a, 0, -a, a, 0, -a, -a, 0, a, -a, 0;
  return p;
}

// A square of half-size a in the z = 0 plane, facing -z (two triangles).
TriangleMesh SquareMesh(double a) {
  TriangleMesh m;
  m.vertices.resize(4, 3);
  m.vertices << -a, -a, 0, a, -a, 0, a, a, 0, -a, a, 0;
  m.faces.resize(2, 3);
  m.faces << 0, 2, 1, 0, 3, 2;
  m.face_colors.setConstant(2, 3, 128);
  return m;
}

// A box with half extents (hx, hy, hz) about the origin.
TriangleMesh Box(double hx, double hy, double hz) {
  return test_util::CentredBox(2 * hx, 2 * hy, 2 * hz, {128, 128, 128});
}

PinholeIntrinsics SmallCamera() {
  PinholeIntrinsics k;
  k.width = 64;
  k.height = 48;
  k.fx = k.fy = 60;
  k.cx = 31.5;
  k.cy = 23.5;
  return k;
}

TEST(BopErrorsTest, MssdAndMspdOfKnownMotions) {
  const Rigid3 gt(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  const Rigid3 shifted(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.003, 0.004, 1));
  EXPECT_NEAR(Mssd(shifted, gt, Square(0.05)), 0.005, 1e-12);
  // Every point at depth 1 moves 0.003 m and 0.004 m: fx * 0.003 and fy * 0.004 pixels.
  PinholeIntrinsics k;  // 525 px
  EXPECT_NEAR(Mspd(shifted, gt, Square(0.05), k), std::hypot(525 * 0.003, 525 * 0.004), 1e-9);
  // A quarter turn about z moves each corner of the square by 2a; a symmetry of a quarter turn
  // takes it back.
  const Eigen::Quaterniond quarter(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  const Rigid3 turned(quarter, gt.translation);
  EXPECT_NEAR(Mssd(turned, gt, Square(0.05)), 0.1, 1e-12);
  EXPECT_NEAR(Mssd(turned, gt, Square(0.05), {Rigid3(quarter, Eigen::Vector3d::Zero())}), 0, 1e-12);
  EXPECT_NEAR(Mspd(turned, gt, Square(0.05), k, {Rigid3(quarter, Eigen::Vector3d::Zero())}), 0, 1e-9);
}

// The nearest hit of the ray through pixel (u, v) with the mesh at the pose (Moller-Trumbore).
double RayCast(const TriangleMesh& mesh, const Rigid3& camera_T_object, const PinholeIntrinsics& k,
               int u, int v) {
  const Eigen::Vector3d dir = k.BackProject(u, v, 1.0).normalized();
  double best = 0;
  for (int f = 0; f < mesh.face_count(); ++f) {
    Eigen::Vector3d p[3];
    for (int j = 0; j < 3; ++j) {
      p[j] = camera_T_object * Eigen::Vector3d(mesh.vertices.row(mesh.faces(f, j)).cast<double>());
    }
    const Eigen::Vector3d e1 = p[1] - p[0], e2 = p[2] - p[0];
    const Eigen::Vector3d h = dir.cross(e2);
    const double a = e1.dot(h);
    if (std::abs(a) < 1e-15) continue;
    const Eigen::Vector3d s = -p[0];
    const double b1 = s.dot(h) / a;
    const Eigen::Vector3d q = s.cross(e1);
    const double b2 = dir.dot(q) / a;
    const double t = e2.dot(q) / a;
    if (b1 < 0 || b2 < 0 || b1 + b2 > 1 || t <= 0) continue;
    if (best == 0 || t < best) best = t;
  }
  return best;
}

TEST(BopErrorsTest, RendererMatchesRayCasting) {
  const TriangleMesh box = Box(0.05, 0.03, 0.02);
  const PinholeIntrinsics k = SmallCamera();
  const Rigid3 pose(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 0.5).normalized())),
                    Eigen::Vector3d(0.01, -0.005, 0.4));
  const std::vector<float> rendered = RenderDistance(box, pose, k);
  int hits = 0, disagreements = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double truth = RayCast(box, pose, k, u, v);
      const float r = rendered[v * k.width + u];
      if ((truth > 0) != (r > 0)) {
        ++disagreements;  // a pixel centre on an edge
        continue;
      }
      if (truth > 0) {
        ++hits;
        EXPECT_NEAR(r, truth, 1e-5) << u << "," << v;
      }
    }
  }
  EXPECT_GT(hits, 100);  // 164 pixels see the box
  EXPECT_LE(disagreements, 2);
}

TEST(BopErrorsTest, VsdOfPlanesFillingTheImage) {
  const PinholeIntrinsics k = SmallCamera();
  const TriangleMesh plane = SquareMesh(5.0);  // far larger than the view at 1 m
  const Rigid3 gt(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
  const std::vector<float> test = RenderDistance(plane, gt, k);
  const std::vector<double> taus = {0.005, 0.02};
  EXPECT_EQ(Vsd(gt, gt, plane, test, k, 0.015, taus), (std::vector<double>{0, 0}));
  // 1 cm further: every pixel visible in both, distances 1 cm (to 0.2 % at the corners) apart.
  const Rigid3 further(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.01));
  EXPECT_EQ(Vsd(further, gt, plane, test, k, 0.015, taus), (std::vector<double>{1, 0}));
  // A small square 1 m to the side: nothing in common, every visible pixel costs.
  const TriangleMesh small = SquareMesh(0.05);
  const std::vector<float> test_small = RenderDistance(small, gt, k);
  const Rigid3 aside(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.2, 0, 1));
  EXPECT_EQ(Vsd(aside, gt, small, test_small, k, 0.015, taus), (std::vector<double>{1, 1}));
  // Nothing visible at all.
  const Rigid3 behind(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(Vsd(behind, behind, small, test_small, k, 0.015, taus), (std::vector<double>{1, 1}));
}

TEST(BopErrorsTest, AverageRecallCountedByHand) {
  BopFrameErrors a;
  a.has_estimate = true;
  a.mssd = 0.012;                    // diameter 0.1: correct from fraction 0.15, 8 of 10
  a.mspd = 12;                       // correct from 15 px, 8 of 10
  a.vsd.assign(10, 0.22);            // correct from threshold 0.25, 6 of 10, for all 10 taus
  a.add = a.adds = 0.009;            // < 0.1 * 0.1
  a.rotation_deg = 3;
  a.translation = 0.01;              // within 5 deg / 5 cm, not 2 deg / 2 cm
  BopFrameErrors b;                  // no estimate
  const BopRecall r = SummarizeBop({a, b}, 0.1, 640, BopRecallOptions());
  EXPECT_DOUBLE_EQ(r.ar_mssd, 0.4);
  EXPECT_DOUBLE_EQ(r.ar_mspd, 0.4);
  EXPECT_DOUBLE_EQ(r.ar_vsd, 0.3);
  EXPECT_NEAR(r.ar, (0.3 + 0.4 + 0.4) / 3, 1e-15);
  EXPECT_DOUBLE_EQ(r.add_recall, 0.5);
  EXPECT_DOUBLE_EQ(r.recall_5deg_5cm, 0.5);
  EXPECT_DOUBLE_EQ(r.recall_2deg_2cm, 0.0);
  EXPECT_DOUBLE_EQ(r.median_rotation_deg, 3);
  // A 1280-pixel-wide image doubles the MSPD thresholds (10..100 px): 12 px is correct for the 9
  // from 20 px on.
  EXPECT_DOUBLE_EQ(SummarizeBop({a, b}, 0.1, 1280, BopRecallOptions()).ar_mspd, 0.45);
}

TEST(BopErrorsTest, ErrorPointsCoverACuboidsFaces) {
  const TriangleMesh box = Box(0.05, 0.03, 0.02);
  const ModelPoints points = ErrorPoints(box, 1000);
  ASSERT_EQ(points.rows(), 1008);
  // Every point lies on the surface, inside the bounds; the diameter is the box's diagonal.
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).transpose();
    const double on_face = std::min({std::abs(std::abs(p.x()) - 0.05), std::abs(std::abs(p.y()) - 0.03),
                                     std::abs(std::abs(p.z()) - 0.02)});
    EXPECT_LT(on_face, 1e-6);
    EXPECT_LE(std::abs(p.x()), 0.05 + 1e-6);
  }
  EXPECT_NEAR(Diameter(points), 2 * std::sqrt(0.05 * 0.05 + 0.03 * 0.03 + 0.02 * 0.02), 1e-6);
  // Area-uniform: the share on the two 0.1 x 0.06 faces is their share of the area.
  int top = 0;
  for (Eigen::Index i = 8; i < points.rows(); ++i) top += std::abs(std::abs(points(i, 2)) - 0.02) < 1e-6;
  const double share = 2 * 0.1 * 0.06 / (2 * (0.1 * 0.06 + 0.1 * 0.04 + 0.06 * 0.04));
  EXPECT_NEAR(top / 1000.0, share, 0.01);
}

}  // namespace
}  // namespace mmh::metrics
