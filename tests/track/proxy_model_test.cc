// The proxy model's samples and closest-point grid against brute force.
#include "track/proxy_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "tests/test_util.h"
#include "tests/track/sim_take.h"

namespace mmh::track {
namespace {

using test_util::ErrorOf;
using ::testing::HasSubstr;

TriangleMesh Box(float sx, float sy, float sz) {
  TriangleMesh box;
  box.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    box.vertices.row(i) << (i & 1 ? sx / 2 : -sx / 2), (i & 2 ? sy / 2 : -sy / 2),
        (i & 4 ? sz : 0.0f);
  }
  const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  box.faces.resize(12, 3);
  for (int f = 0; f < 12; ++f) box.faces.row(f) << faces[f][0], faces[f][1], faces[f][2];
  box.face_colors.setConstant(12, 3, 200);
  return box;
}

TEST(ProxyModelTest, SamplesLieOnTheSurfaceWithOutwardNormals) {
  const ProxyModel model(Box(0.06f, 0.03f, 0.09f), ProxyModelOptions(), "box");
  // Area 2 (0.06 0.03 + 0.06 0.09 + 0.03 0.09) = 0.0198 m^2 at 1.5 mm spacing: about 8800.
  EXPECT_NEAR(static_cast<double>(model.points().size()), 0.0198 / (0.0015 * 0.0015), 30);
  for (size_t i = 0; i < model.points().size(); ++i) {
    const Eigen::Vector3f& p = model.points()[i];
    const Eigen::Vector3f& n = model.normals()[i];
    // On the face its normal names: the coordinate along the normal is at the box's extent.
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const float extent[3][2] = {{-0.03f, 0.03f}, {-0.015f, 0.015f}, {0.0f, 0.09f}};
    ASSERT_NEAR(p[axis], extent[axis][n[axis] > 0 ? 1 : 0], 1e-6) << i;
  }
  EXPECT_NEAR(model.center().z(), 0.045f, 1e-6);
  EXPECT_NEAR(model.centroid().z(), 0.045f, 1e-3);
}

TEST(ProxyModelTest, GridGivesTheNearestSampleWithinACell) {
  const test_take::SimTake take;
  const ProxyModel model(take.model(), ProxyModelOptions(), "soldier");
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.08f, 0.14f);
  int exact = 0, checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3f q(u(rng) * 0.6f, u(rng) * 0.4f, u(rng));
    const int c = model.Closest(q);
    if (c < 0) continue;
    ++checked;
    float best = 1e30f;
    int brute = -1;
    for (size_t i = 0; i < model.points().size(); ++i) {
      const float d = (model.points()[i] - q).squaredNorm();
      if (d < best) {
        best = d;
        brute = static_cast<int>(i);
      }
    }
    exact += brute == c;
    // The grid answers for the cell's centre: at most a cell diagonal farther than the nearest.
    ASSERT_LE((model.points()[c] - q).norm(), std::sqrt(best) + 0.002f * std::sqrt(3.0f) + 1e-6f);
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(exact, checked / 4);
  EXPECT_EQ(model.Closest(Eigen::Vector3f(1, 1, 1)), -1);
}

TEST(ProxyModelTest, BigModelsBuildQuicklyAndNonsenseIsRejected) {
  const auto start = std::chrono::steady_clock::now();
  const ProxyModel big(Box(0.25f, 0.25f, 0.25f), ProxyModelOptions(), "cube");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
  EXPECT_THAT(ErrorOf([] { ProxyModel m(Box(30, 30, 30), ProxyModelOptions(), "mm.ply"); }),
              HasSubstr("scale of 0.001"));
  ProxyModelOptions bad;
  bad.grid_resolution = 0;
  EXPECT_THAT(ErrorOf([&] { ProxyModel m(Box(0.1f, 0.1f, 0.1f), bad, "x"); }),
              HasSubstr("model.grid_resolution"));
}

}  // namespace
}  // namespace mmh::track
