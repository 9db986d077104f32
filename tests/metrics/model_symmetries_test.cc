// BOP symmetries (models_info.json) and their use in the pose errors, against hand-computed
// values: a box's half turns about axes through its off-origin centre, a cylinder's continuous
// symmetry discretised as bop_toolkit does (count, angles, the fixed axis), MSSD and the rotation
// error of a symmetric estimate, the visib_fract filter, and bad files.
#include "metrics/model_symmetries.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "metrics/bop_errors.h"
#include "metrics/pose_evaluation.h"
#include "tests/test_util.h"

namespace mmh::metrics {
namespace {

using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;

// A box 0.1 x 0.2 x 0.3 m centred at (0.01, 0, 0): its corners.
ModelPoints BoxCorners() {
  ModelPoints p(8, 3);
  for (int i = 0; i < 8; ++i) {
    p.row(i) << 0.01 + (i & 1 ? 0.05 : -0.05), (i & 2 ? 0.1 : -0.1), (i & 4 ? 0.15 : -0.15);
  }
  return p;
}

// The box's half turn about z through its centre, in millimetres as BOP writes it: R = diag(-1,
// -1, 1), t = c - R c = (20, 0, 0) mm.
constexpr char kBoxInfo[] =
    R"({"3": {"diameter": 374.2, "symmetries_discrete": [[-1, 0, 0, 20, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]]},
        "5": {"diameter": 100}})";

TEST(ModelSymmetriesTest, ReadsDiscreteSymmetriesInTheModelsUnit) {
  TempDir dir;
  WriteText(dir / "models_info.json", kBoxInfo);
  const auto objects = ReadModelsInfo(dir / "models_info.json", 0.001);
  ASSERT_EQ(objects.size(), 2u);
  ASSERT_EQ(objects.at(3).discrete.size(), 1u);
  EXPECT_TRUE(objects.at(5).discrete.empty());
  const Rigid3& s = objects.at(3).discrete[0];
  EXPECT_NEAR(s.translation.x(), 0.02, 1e-12);
  EXPECT_NEAR(RotationAngle(s.rotation, Eigen::Quaterniond::Identity()), kPi, 1e-9);
  // The centre stays where it is.
  EXPECT_NEAR((s * Eigen::Vector3d(0.01, 0, 0) - Eigen::Vector3d(0.01, 0, 0)).norm(), 0, 1e-12);
  // Without continuous symmetries: the identity and the discrete one.
  EXPECT_EQ(SymmetryTransformations(objects.at(3)).size(), 2u);
}

TEST(ModelSymmetriesTest, BoxEstimateTurnedByItsSymmetryHasNoError) {
  const ModelPoints corners = BoxCorners();
  const Rigid3 camera_T_gt(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())),
                           Eigen::Vector3d(0.1, 0, 0.8));
  const Rigid3 half_turn(Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(0.02, 0, 0));
  const Rigid3 camera_T_est = camera_T_gt * half_turn;
  // Without the symmetry every corner moves by twice its distance from the axis:
  // 2 sqrt(0.05^2 + 0.1^2).
  EXPECT_NEAR(Mssd(camera_T_est, camera_T_gt, corners), 2 * std::sqrt(0.05 * 0.05 + 0.1 * 0.1),
              1e-12);
  EXPECT_NEAR(Mssd(camera_T_est, camera_T_gt, corners, {half_turn}), 0, 1e-12);
  // The rotation and translation errors against the nearest symmetric truth: 0, not 180 deg.
  TriangleMesh box;
  box.vertices = corners.cast<float>();
  box.faces.resize(0, 3);
  EvaluationFrame frame;
  frame.camera_T_truth = camera_T_gt;
  frame.camera_T_estimate = camera_T_est;
  frame.intrinsics.width = 640;
  frame.intrinsics.height = 480;
  frame.intrinsics.fx = frame.intrinsics.fy = 500;
  frame.intrinsics.cx = 320;
  frame.intrinsics.cy = 240;
  PoseEvaluationOptions options;
  options.surface_points = 0;
  options.vsd = false;
  const ObjectEvaluation with = EvaluateObject(3, {frame}, box, {half_turn}, options);
  EXPECT_NEAR(with.errors[0].rotation_deg, 0, 1e-6);
  EXPECT_NEAR(with.errors[0].translation, 0, 1e-12);
  EXPECT_EQ(with.recall.recall_2deg_2cm, 1.0);
  EXPECT_EQ(with.symmetries, 1);
  const ObjectEvaluation without = EvaluateObject(3, {frame}, box, {}, options);
  EXPECT_NEAR(without.errors[0].rotation_deg, 180, 1e-6);
  // The model origin is 1 cm off the axis: it moves by 2 cm.
  EXPECT_NEAR(without.errors[0].translation, 0.02, 1e-12);
}

TEST(ModelSymmetriesTest, CylinderIsDiscretisedAsBopToolkitDoes) {
  ModelSymmetries cylinder;
  ContinuousSymmetry axis;  // z through (0.01, -0.02, 0)
  axis.offset = Eigen::Vector3d(0.01, -0.02, 0);
  cylinder.continuous.push_back(axis);
  // max_step 0.5: n = ceil(pi / 0.5) = 7 steps of 2 pi / 7, the identity first.
  const std::vector<Rigid3> turns = SymmetryTransformations(cylinder, 0.5);
  ASSERT_EQ(turns.size(), 7u);
  for (int k = 0; k < 7; ++k) {
    const double angle = RotationAngle(turns[k].rotation, Eigen::Quaterniond::Identity());
    EXPECT_NEAR(angle, std::min(2 * kPi * k / 7, 2 * kPi - 2 * kPi * k / 7), 1e-9) << k;
    // Points on the axis stay.
    EXPECT_NEAR((turns[k] * Eigen::Vector3d(0.01, -0.02, 0.3) - Eigen::Vector3d(0.01, -0.02, 0.3))
                    .norm(),
                0, 1e-12);
  }
  // With a discrete half turn about x besides: (1 + 1) x 7 transformations.
  cylinder.discrete.emplace_back(
      Eigen::Quaterniond(Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX())), Eigen::Vector3d::Zero());
  EXPECT_EQ(SymmetryTransformations(cylinder, 0.5).size(), 14u);
  // BOP's step 0.01: 315 steps.
  cylinder.discrete.clear();
  EXPECT_EQ(SymmetryTransformations(cylinder).size(), 315u);
}

TEST(ModelSymmetriesTest, CylinderMssdIsTheDiscretisationsChord) {
  // A ring of radius 5 cm about z; the estimate turned by 1.5 steps of 2 pi / 7 about the axis:
  // the nearest step is half a step away, so every point is off by the chord 2 r sin(step / 4).
  ModelPoints ring(36, 3);
  for (int i = 0; i < 36; ++i) {
    ring.row(i) << 0.05 * std::cos(i * kPi / 18), 0.05 * std::sin(i * kPi / 18), 0.02;
  }
  ModelSymmetries cylinder;
  cylinder.continuous.emplace_back();
  std::vector<Rigid3> symmetries = SymmetryTransformations(cylinder, 0.5);
  symmetries.erase(symmetries.begin());
  const double step = 2 * kPi / 7;
  const Rigid3 camera_T_gt(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 0.7));
  const Rigid3 camera_T_est =
      camera_T_gt * Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(1.5 * step, Eigen::Vector3d::UnitZ())),
                           Eigen::Vector3d::Zero());
  EXPECT_NEAR(Mssd(camera_T_est, camera_T_gt, ring, symmetries), 2 * 0.05 * std::sin(step / 4),
              1e-12);
  EXPECT_NEAR(Mssd(camera_T_est, camera_T_gt, ring), 2 * 0.05 * std::sin(1.5 * step / 2), 1e-12);
}

TEST(ModelSymmetriesTest, InstancesBelowTheVisibleFractionAreLeftOut) {
  TriangleMesh box;
  box.vertices = BoxCorners().cast<float>();
  box.faces.resize(0, 3);
  std::vector<EvaluationFrame> frames(4);
  const double visible[4] = {0.05, 0.1, -1.0, 0.9};
  for (int i = 0; i < 4; ++i) {
    frames[i].frame = i;
    frames[i].visible_fraction = visible[i];
    frames[i].camera_T_truth = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1));
    frames[i].intrinsics.width = 640;
    frames[i].intrinsics.height = 480;
    frames[i].intrinsics.fx = frames[i].intrinsics.fy = 500;
  }
  PoseEvaluationOptions options;
  options.vsd = false;
  const ObjectEvaluation e = EvaluateObject(1, frames, box, {}, options);
  // 0.05 < 0.1 is left out; 0.1 itself, an unknown one and 0.9 count.
  EXPECT_EQ(e.low_visibility, 1);
  ASSERT_EQ(e.frames.size(), 3u);
  EXPECT_EQ(e.frames[0].frame, 1);
  EXPECT_EQ(e.recall.frames, 3);
}

TEST(ModelSymmetriesTest, BadFilesNameTheObjectAndTheKey) {
  TempDir dir;
  auto error = [&](const std::string& text) {
    WriteText(dir / "models_info.json", text);
    try {
      ReadModelsInfo(dir / "models_info.json", 0.001);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error(R"({"1": {"symmetries_discrete": [[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0]]}})"),
              HasSubstr("object \"1\".symmetries_discrete[0]"));
  EXPECT_THAT(
      error(R"({"2": {"symmetries_discrete": [[2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]]}})"),
      HasSubstr("a rotation"));
  EXPECT_THAT(error(R"({"4": {"symmetries_continuous": [{"axis": [0, 0, 0], "offset": [0, 0, 0]}]}})"),
              HasSubstr("symmetries_continuous[0].axis"));
  EXPECT_THAT(error(R"({"x": {}})"), HasSubstr("not an integer object id"));
  EXPECT_THAT(error("[1, 2]"), HasSubstr("models_info.json"));
}

}  // namespace
}  // namespace mmh::metrics
