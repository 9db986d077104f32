// Tests of core/rigid3.h: composition, inverse, point mapping, interpolation, rotation angle.
#include "core/rigid3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace mmh {
namespace {

Eigen::Isometry3d ToIsometry(const Rigid3& a_T_b) {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = a_T_b.rotation.toRotationMatrix();
  iso.translation() = a_T_b.translation;
  return iso;
}

Rigid3 RandomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  return Rigid3(q, Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
}

Rigid3 AxisAngle(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())), t);
}

void ExpectMatrixNear(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b, double tol) {
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      EXPECT_NEAR(a(r, c), b(r, c), tol) << "at (" << r << "," << c << ")";
  }
}

TEST(Rigid3, IdentityIsNeutral) {
  const Rigid3 identity = Rigid3::Identity();
  EXPECT_EQ(identity.rotation.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  EXPECT_EQ(identity.translation, Eigen::Vector3d::Zero());
  const Eigen::Vector3d p(1.0, -2.0, 3.5);
  EXPECT_EQ(identity * p, p);

  std::mt19937_64 rng(1);
  const Rigid3 a_T_b = RandomPose(rng);
  ExpectMatrixNear(ToIsometry(identity * a_T_b).matrix(), ToIsometry(a_T_b).matrix(), 1e-15);
  ExpectMatrixNear(ToIsometry(a_T_b * identity).matrix(), ToIsometry(a_T_b).matrix(), 1e-15);
}

TEST(Rigid3, CompositionMatchesEigenIsometry) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 100; ++trial) {
    const Rigid3 a_T_b = RandomPose(rng);
    const Rigid3 b_T_c = RandomPose(rng);
    const Rigid3 a_T_c = a_T_b * b_T_c;
    const Eigen::Isometry3d expected = ToIsometry(a_T_b) * ToIsometry(b_T_c);
    ExpectMatrixNear(ToIsometry(a_T_c).matrix(), expected.matrix(), 1e-12);
  }
}

TEST(Rigid3, CompositionOrderIsFrameChaining) {
  // a_T_b: translate by (1,0,0); b_T_c: rotate 90 degrees about z. A point at c's x axis (1,0,0)
  // is at (0,1,0) in b, and at (1,1,0) in a.
  const Rigid3 a_T_b(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  const Rigid3 b_T_c =
      AxisAngle(std::numbers::pi / 2, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero());
  const Eigen::Vector3d p_c(1, 0, 0);
  const Eigen::Vector3d p_a = (a_T_b * b_T_c) * p_c;
  EXPECT_NEAR(p_a.x(), 1.0, 1e-15);
  EXPECT_NEAR(p_a.y(), 1.0, 1e-15);
  EXPECT_NEAR(p_a.z(), 0.0, 1e-15);
  // The other order gives a different point: (0, 2, 0) -> rotation of (2,0,0).
  const Eigen::Vector3d wrong = (b_T_c * a_T_b) * p_c;
  EXPECT_NEAR(wrong.y(), 2.0, 1e-15);
}

TEST(Rigid3, CompositionIsAssociative) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Rigid3 a = RandomPose(rng), b = RandomPose(rng), c = RandomPose(rng);
    ExpectMatrixNear(ToIsometry((a * b) * c).matrix(), ToIsometry(a * (b * c)).matrix(), 1e-12);
  }
}

TEST(Rigid3, PointMappingMatchesEigenIsometry) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 2.0);
  for (int trial = 0; trial < 100; ++trial) {
    const Rigid3 a_T_b = RandomPose(rng);
    const Eigen::Vector3d p_b(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d got = a_T_b * p_b;
    const Eigen::Vector3d expected = ToIsometry(a_T_b) * p_b;
    EXPECT_LT((got - expected).norm(), 1e-12);
  }
}

TEST(Rigid3, PointMappingOfCompositionEqualsSuccessiveMapping) {
  std::mt19937_64 rng(5);
  const Rigid3 a_T_b = RandomPose(rng), b_T_c = RandomPose(rng);
  const Eigen::Vector3d p_c(0.3, -0.2, 1.7);
  EXPECT_LT(((a_T_b * b_T_c) * p_c - a_T_b * (b_T_c * p_c)).norm(), 1e-12);
}

TEST(Rigid3, InverseMatchesEigenIsometryInverse) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const Rigid3 a_T_b = RandomPose(rng);
    const Rigid3 b_T_a = a_T_b.Inverse();
    ExpectMatrixNear(ToIsometry(b_T_a).matrix(), ToIsometry(a_T_b).inverse().matrix(), 1e-12);
    // a_T_b * b_T_a = identity, both ways.
    ExpectMatrixNear(ToIsometry(a_T_b * b_T_a).matrix(), Eigen::Matrix4d::Identity(), 1e-12);
    ExpectMatrixNear(ToIsometry(b_T_a * a_T_b).matrix(), Eigen::Matrix4d::Identity(), 1e-12);
    // Mapping a point there and back.
    const Eigen::Vector3d p_b(0.1 * trial, -1.0, 2.0);
    EXPECT_LT((b_T_a * (a_T_b * p_b) - p_b).norm(), 1e-12);
  }
}

TEST(Rigid3, InterpolateEndpoints) {
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 50; ++trial) {
    const Rigid3 from = RandomPose(rng), to = RandomPose(rng);
    const Rigid3 at0 = Interpolate(from, to, 0.0);
    const Rigid3 at1 = Interpolate(from, to, 1.0);
    EXPECT_LT((at0.translation - from.translation).norm(), 1e-14);
    EXPECT_LT((at1.translation - to.translation).norm(), 1e-14);
    EXPECT_LT(RotationAngle(at0.rotation, from.rotation), 1e-7);
    EXPECT_LT(RotationAngle(at1.rotation, to.rotation), 1e-7);
    // The same rotation matrices (angle comparison above is coarse near zero).
    EXPECT_TRUE(at0.rotation.toRotationMatrix().isApprox(from.rotation.toRotationMatrix(), 1e-12));
    EXPECT_TRUE(at1.rotation.toRotationMatrix().isApprox(to.rotation.toRotationMatrix(), 1e-12));
    EXPECT_NEAR(at0.rotation.norm(), 1.0, 1e-15);
    EXPECT_NEAR(at1.rotation.norm(), 1.0, 1e-15);
  }
}

TEST(Rigid3, InterpolateMidpointAboutOneAxis) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -1).normalized();
  const Rigid3 from = AxisAngle(0.2, axis, Eigen::Vector3d(0, 0, 0));
  const Rigid3 to = AxisAngle(1.0, axis, Eigen::Vector3d(2, -4, 6));
  const Rigid3 mid = Interpolate(from, to, 0.5);
  const Rigid3 expected = AxisAngle(0.6, axis, Eigen::Vector3d(1, -2, 3));
  EXPECT_LT((mid.translation - expected.translation).norm(), 1e-15);
  EXPECT_NEAR(RotationAngle(mid.rotation, expected.rotation), 0.0, 1e-7);
  EXPECT_TRUE(
      mid.rotation.toRotationMatrix().isApprox(expected.rotation.toRotationMatrix(), 1e-12));
  EXPECT_NEAR(RotationAngle(from.rotation, mid.rotation), 0.4, 1e-12);
  EXPECT_NEAR(RotationAngle(mid.rotation, to.rotation), 0.4, 1e-12);

  // A quarter of the way.
  const Rigid3 quarter = Interpolate(from, to, 0.25);
  EXPECT_NEAR(RotationAngle(from.rotation, quarter.rotation), 0.2, 1e-12);
  EXPECT_LT((quarter.translation - Eigen::Vector3d(0.5, -1, 1.5)).norm(), 1e-15);
}

TEST(Rigid3, InterpolateTakesShorterArcWhenQuaternionSignsDiffer) {
  // from: identity; to: 120 degrees about z, but stored as -q (w < 0). The long way round would be
  // 240 degrees; the shorter arc's midpoint is 60 degrees about z.
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Quaterniond q_to(Eigen::AngleAxisd(2.0 * std::numbers::pi / 3.0, z));
  const Eigen::Quaterniond minus_q_to(-q_to.w(), -q_to.x(), -q_to.y(), -q_to.z());
  ASSERT_LT(Eigen::Quaterniond::Identity().dot(minus_q_to), 0.0);

  const Rigid3 from = Rigid3::Identity();
  const Rigid3 to(minus_q_to, Eigen::Vector3d::Zero());
  const Rigid3 mid = Interpolate(from, to, 0.5);
  const Eigen::Quaterniond expected(Eigen::AngleAxisd(std::numbers::pi / 3.0, z));
  EXPECT_NEAR(RotationAngle(mid.rotation, expected), 0.0, 1e-7);
  EXPECT_TRUE(mid.rotation.toRotationMatrix().isApprox(expected.toRotationMatrix(), 1e-12));
  EXPECT_NEAR(RotationAngle(from.rotation, mid.rotation), std::numbers::pi / 3.0, 1e-12);

  // Same result when `from` carries the negative sign instead.
  const Rigid3 from_neg(Eigen::Quaterniond(-1, 0, 0, 0), Eigen::Vector3d::Zero());
  const Rigid3 to_pos(q_to, Eigen::Vector3d::Zero());
  const Rigid3 mid2 = Interpolate(from_neg, to_pos, 0.5);
  EXPECT_TRUE(mid2.rotation.toRotationMatrix().isApprox(expected.toRotationMatrix(), 1e-12));

  // And every intermediate weight lies on the shorter arc: angle from `from` grows linearly.
  for (double w = 0.0; w <= 1.0; w += 0.125) {
    const Rigid3 r = Interpolate(from, to, w);
    EXPECT_NEAR(RotationAngle(from.rotation, r.rotation), w * 2.0 * std::numbers::pi / 3.0, 1e-7)
        << "weight " << w;
    EXPECT_NEAR(r.rotation.norm(), 1.0, 1e-14);
  }
}

TEST(Rigid3, InterpolateBetweenEqualRotationsOfOppositeSign) {
  // q and -q: the same rotation; every interpolated rotation must be that rotation.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0, 1, 1).normalized()));
  const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
  const Rigid3 from(q, Eigen::Vector3d::Zero()), to(minus_q, Eigen::Vector3d::Ones());
  for (double w : {0.0, 0.3, 0.5, 0.9, 1.0}) {
    const Rigid3 r = Interpolate(from, to, w);
    EXPECT_TRUE(r.rotation.toRotationMatrix().isApprox(q.toRotationMatrix(), 1e-12)) << w;
    EXPECT_LT((r.translation - Eigen::Vector3d::Constant(w)).norm(), 1e-15);
  }
}

TEST(Rigid3, RotationAngle) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.4, axis));
  for (double angle : {0.1, 0.5, 1.0, std::numbers::pi / 2, 2.5, 3.0}) {
    const Eigen::Quaterniond b =
        a * Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()));
    EXPECT_NEAR(RotationAngle(a, b), angle, 1e-12) << angle;
    EXPECT_NEAR(RotationAngle(b, a), angle, 1e-12) << angle;
  }
  // A rotation by pi: the largest angle.
  const Eigen::Quaterniond half_turn(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationAngle(Eigen::Quaterniond::Identity(), half_turn), std::numbers::pi, 1e-7);
  // Rotations by more than pi are the same as the complementary rotation: result in [0, pi].
  const Eigen::Quaterniond three_half(
      Eigen::AngleAxisd(1.5 * std::numbers::pi, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(RotationAngle(Eigen::Quaterniond::Identity(), three_half), 0.5 * std::numbers::pi,
              1e-12);
}

TEST(Rigid3, RotationAngleIgnoresQuaternionSign) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
  EXPECT_EQ(RotationAngle(q, q), 0.0);
  EXPECT_EQ(RotationAngle(q, minus_q), 0.0);
  EXPECT_NEAR(RotationAngle(Eigen::Quaterniond::Identity(), minus_q), 1.1, 1e-12);
}

TEST(Rigid3, RotationAngleStaysInRange) {
  std::mt19937_64 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    const Rigid3 a = RandomPose(rng), b = RandomPose(rng);
    const double angle = RotationAngle(a.rotation, b.rotation);
    EXPECT_GE(angle, 0.0);
    EXPECT_LE(angle, std::numbers::pi);
    // Agrees with the angle of the relative rotation matrix.
    const Eigen::AngleAxisd relative(a.rotation.toRotationMatrix().transpose() *
                                     b.rotation.toRotationMatrix());
    EXPECT_NEAR(angle, std::abs(relative.angle()), 1e-7);
  }
}

}  // namespace
}  // namespace mmh
