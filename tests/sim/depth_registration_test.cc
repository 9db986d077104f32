// Registration of depth into another camera against the geometry it must reproduce: the same
// camera, a plane seen from beside, a board before a wall (the gap the source camera did not see
// and the z-buffer where the board moves over the wall) and a finer destination grid.
#include "sim/depth_registration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/error.h"

namespace mmh::sim {
namespace {

PinholeIntrinsics Intrinsics(double f, int width = 160, int height = 120) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = f;
  k.cx = (width - 1) / 2.0;
  k.cy = (height - 1) / 2.0;
  return k;
}

Rigid3 Beside(double x) { return Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0, 0)); }

TEST(DepthRegistration, TheSameCameraGivesTheSameImage) {
  const PinholeIntrinsics k = Intrinsics(150);
  std::vector<float> depth(k.width * k.height);
  for (size_t p = 0; p < depth.size(); ++p)
    depth[p] = p % 7 == 0 ? 0.0f : 0.6f + 0.001f * (p % 500);
  EXPECT_EQ(RegisterDepth(depth, k, k, Rigid3::Identity()), depth);
}

TEST(DepthRegistration, APlaneSeenFromBesideIsShiftedWhole) {
  // A fronto-parallel plane at 1 m seen from a camera 2.5 cm to -x: in the destination every
  // pixel but a strip of f * 0.025 / 1 = 3.75 px on the +x side has the plane's depth.
  const PinholeIntrinsics k = Intrinsics(150);
  const std::vector<float> plane(k.width * k.height, 1.0f);
  const std::vector<float> out = RegisterDepth(plane, k, k, Beside(-0.025));
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const float z = out[v * k.width + u];
      if (u < k.width - 4) {
        EXPECT_FLOAT_EQ(z, 1.0f) << u << " " << v;
      } else {
        EXPECT_EQ(z, 0.0f) << u << " " << v;
      }
    }
  }
}

TEST(DepthRegistration, ABoardBeforeAWallLeavesTheUnseenGapAndCoversTheWall) {
  // Source: a board at 0.5 m over columns [60, 100) before a wall at 1.5 m. The destination
  // camera sits 2.5 cm along -x of the source: the board moves right by f 0.025 / 0.5 = 7.5 px,
  // the wall by 2.5 px, so right of the board a gap of 5 px opens (wall the source did not see)
  // and on its left the board covers 5 px of wall (the z-buffer keeps the board).
  const PinholeIntrinsics k = Intrinsics(150);
  std::vector<float> depth(k.width * k.height, 1.5f);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 60; u < 100; ++u) depth[v * k.width + u] = 0.5f;
  }
  const std::vector<float> out = RegisterDepth(depth, k, k, Beside(0.025));
  const int v = 60;
  const float* row = out.data() + v * k.width;
  // The board's footprint spans [59.5 + 7.5, 99.5 + 7.5) = [67, 107): centres 67 .. 106.
  for (int u = 67; u <= 106; ++u) EXPECT_FLOAT_EQ(row[u], 0.5f) << u;
  // The wall right of the board starts at 100 - 0.5 + 2.5 = 102: covered by the board up to 106,
  // and the wall resumes at 107; nothing is missing there. Left of the board the wall ends at
  // 59.5 + 2.5 = 62: centres 62 .. 66 are the gap.
  EXPECT_FLOAT_EQ(row[61], 1.5f);
  for (int u = 62; u <= 66; ++u) EXPECT_EQ(row[u], 0.0f) << u;
  EXPECT_FLOAT_EQ(row[107], 1.5f);
}

TEST(DepthRegistration, AFinerGridIsCoveredAndGrowthWidensNearSurfaces) {
  // Onto a grid of twice the focal length: a plane leaves no hole inside.
  const PinholeIntrinsics from = Intrinsics(150, 80, 60), to = Intrinsics(300, 160, 120);
  std::vector<float> depth(from.width * from.height, 1.0f);
  std::vector<float> out = RegisterDepth(depth, from, to, Rigid3::Identity());
  for (float z : out) EXPECT_FLOAT_EQ(z, 1.0f);
  // A near square at 0.5 m over source columns [30, 50), rows [20, 40): exactly destination
  // columns [59.5 + 0.5, 99.5 + 0.5) -> 60 .. 99; grown by one destination pixel, 59 .. 100.
  for (int v = 20; v < 40; ++v) {
    for (int u = 30; u < 50; ++u) depth[v * from.width + u] = 0.5f;
  }
  auto near_columns = [&](double growth) {
    DepthRegistrationOptions o;
    o.footprint_growth_px = growth;
    out = RegisterDepth(depth, from, to, Rigid3::Identity(), o);
    int n = 0;
    for (int u = 0; u < to.width; ++u) n += out[60 * to.width + u] == 0.5f;
    return n;
  };
  EXPECT_EQ(near_columns(0.0), 40);
  EXPECT_EQ(near_columns(1.0), 42);
}

// Cameras side by side take a shortcut (a point keeps its depth and its row); any other pose
// projects each footprint's corners. A rotation of a micro-radian forces the general way: the two
// agree but for centres within rounding of a footprint's side.
TEST(DepthRegistration, TheSideBySideShortcutAgreesWithTheGeneralProjection) {
  // (Focal lengths whose footprint sides never fall on a centre exactly: there the half-open
  // rule, not the projection, decides, and a micro-radian tips it.)
  const PinholeIntrinsics from = Intrinsics(160), to = Intrinsics(145.3);
  std::vector<float> depth(from.width * from.height, 1.5f);
  for (int v = 30; v < 90; ++v) {
    for (int u = 50; u < 110; ++u) depth[v * from.width + u] = 0.55f + 0.002f * (u - 50);
  }
  for (int v = 0; v < from.height; v += 7) depth[v * from.width + 70] = 0;
  const Rigid3 side(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.025, 0, 0));
  const Rigid3 turned(Eigen::Quaterniond(Eigen::AngleAxisd(1e-6, Eigen::Vector3d::UnitY())),
                      side.translation);
  std::vector<int32_t> a_source, b_source;
  const std::vector<float> a = RegisterDepth(depth, from, to, side, {}, &a_source);
  const std::vector<float> b = RegisterDepth(depth, from, to, turned, {}, &b_source);
  int differ = 0;
  for (size_t p = 0; p < a.size(); ++p) {
    differ += a_source[p] != b_source[p];
    if (a_source[p] == b_source[p] && a[p] != 0) {
      EXPECT_NEAR(a[p], b[p], 1e-5);
    }
  }
  EXPECT_LT(differ, static_cast<int>(a.size() / 200)) << differ;
  // A plane turned by 2 degrees about the vertical stays whole inside.
  const Rigid3 turn(Eigen::Quaterniond(Eigen::AngleAxisd(0.035, Eigen::Vector3d::UnitY())),
                    Eigen::Vector3d::Zero());
  const std::vector<float> plane =
      RegisterDepth(std::vector<float>(depth.size(), 1.0f), from, from, turn);
  for (int v = 10; v < from.height - 10; ++v) {
    for (int u = 20; u < from.width - 20; ++u) EXPECT_GT(plane[v * from.width + u], 0) << u;
  }
}

// The side-by-side shortcut against brute force: every destination centre tested against every
// source pixel's footprint, u0 - g <= x < u1 + g and v0 - g <= y < v1 + g with the footprint's
// edges computed as the documented formula does, the nearest depth winning and ties the lowest
// source index. Random depths with holes (0 and NaN), runs of equal depths (ties) and near
// surfaces, onto a coarser and a finer grid, with and without growth.
TEST(DepthRegistration, TheSideBySideShortcutEqualsBruteForce) {
  std::mt19937 random(23);
  std::uniform_real_distribution<float> depth_of(0.45f, 3.0f);
  std::uniform_int_distribution<int> kind(0, 9);
  for (const double to_f : {52.7, 61.0, 118.3}) {
    for (const double g : {0.0, 0.05, 0.6}) {
      const PinholeIntrinsics from = Intrinsics(58.1, 40, 30), to = Intrinsics(to_f, 48, 36);
      std::vector<float> depth(from.width * from.height);
      for (float& z : depth) {
        const int k = kind(random);
        z = k == 0 ? 0.0f : k == 1 ? std::nanf("") : k < 4 ? 1.25f : depth_of(random);
      }
      const Rigid3 to_T_from = Beside(-0.025);
      DepthRegistrationOptions options;
      options.footprint_growth_px = g;
      std::vector<int32_t> source;
      const std::vector<float> out = RegisterDepth(depth, from, to, to_T_from, options, &source);
      const double su = to.fx / from.fx, sv = to.fy / from.fy;
      for (int y = 0; y < to.height; ++y) {
        for (int x = 0; x < to.width; ++x) {
          float best = 0;
          int32_t best_index = -1;
          for (int v = 0; v < from.height; ++v) {
            const double v0 = sv * (v - 0.5 - from.cy) + to.cy,
                         v1 = sv * (v + 0.5 - from.cy) + to.cy;
            if (!(v0 - g <= y && y < v1 + g)) continue;
            for (int u = 0; u < from.width; ++u) {
              const float z = depth[v * from.width + u];
              if (!(std::isfinite(z) && z > 0)) continue;
              const double shift = to.fx * to_T_from.translation.x() / z + to.cx;
              const double u0 = su * (u - 0.5 - from.cx) + shift,
                           u1 = su * (u + 0.5 - from.cx) + shift;
              if (!(u0 - g <= x && x < u1 + g)) continue;
              if (best_index < 0 || z < best) {
                best = z;
                best_index = v * from.width + u;
              }
            }
          }
          const size_t p = static_cast<size_t>(y) * to.width + x;
          ASSERT_EQ(source[p], best_index)
              << "f " << to_f << ", g " << g << ", x " << x << ", y " << y;
          ASSERT_EQ(out[p], best) << x << ", " << y;
        }
      }
    }
  }
}

TEST(DepthRegistration, BadInputNamesTheField) {
  const PinholeIntrinsics k = Intrinsics(150);
  EXPECT_THROW(RegisterDepth(std::vector<float>(10, 1.0f), k, k, Rigid3::Identity()), InputError);
  DepthRegistrationOptions o;
  o.footprint_growth_px = -1;
  try {
    RegisterDepth(std::vector<float>(k.width * k.height, 1.0f), k, k, Rigid3::Identity(), o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("registration.footprint_growth_px"), std::string::npos);
  }
}

}  // namespace
}  // namespace mmh::sim
