// The table plane against analytic planes: a synthetic depth image of a table top above a floor,
// seen by a pitched camera.
#include "track/table_plane.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace mmh::track {
namespace {

using ::testing::HasSubstr;

// A camera 0.75 m above a table top (z = 0, |x| < 0.6, |y| < 0.4) and 1.5 m above the floor,
// at table (0, -0.9, 0.75) looking at the origin: every pixel's depth by ray casting.
struct Scene {
  Rigid3 camera_T_table;
  RgbdFrame frame;
};

Scene MakeScene() {
  Scene scene;
  const Eigen::Vector3d eye(0, -0.9, 0.75);
  const Eigen::Vector3d forward = (-eye).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d table_R_camera;
  table_R_camera << right, down, forward;
  const Rigid3 table_T_camera(Eigen::Quaterniond(table_R_camera), eye);
  scene.camera_T_table = table_T_camera.Inverse();
  RgbdFrame& f = scene.frame;
  f.depth.assign(640 * 480, 0);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d ray = table_R_camera * f.depth_intrinsics.BackProject(u, v, 1.0);
      if (ray.z() >= 0) continue;
      double t = -eye.z() / ray.z();  // the table top's plane
      Eigen::Vector3d p = eye + t * ray;
      if (std::abs(p.x()) > 0.6 || std::abs(p.y()) > 0.4) {
        t = -(eye.z() + 0.75) / ray.z();  // the floor
        p = eye + t * ray;
      }
      const double z = t;  // depth along the optical axis: t times the ray's z in the camera (1)
      if (z < 4.0) f.depth[v * 640 + u] = static_cast<uint16_t>(std::lround(z / f.depth_scale));
    }
  }
  return scene;
}

TEST(TablePlaneTest, FindsTheTableNotTheFloor) {
  const Scene scene = MakeScene();
  std::string why;
  for (const bool calibrated : {false, true}) {
    const auto plane = EstimateTablePlane(
        scene.frame, TablePlaneOptions(),
        calibrated ? std::optional<Rigid3>(scene.camera_T_table) : std::nullopt, &why);
    ASSERT_TRUE(plane) << why;
    const Eigen::Vector3d up = scene.camera_T_table.rotation * Eigen::Vector3d::UnitZ();
    EXPECT_LT(std::acos(std::min(1.0, plane->normal.dot(up))), 0.2 * M_PI / 180) << calibrated;
    EXPECT_NEAR(plane->offset, 0.75, 0.002) << calibrated;  // the camera's height above the table
    EXPECT_GE(plane->candidates, 2);
    const Rigid3 camera_T_table = TableFrameOnPlane(*plane, scene.camera_T_table);
    EXPECT_LT((camera_T_table.translation - scene.camera_T_table.translation).norm(), 0.003);
    EXPECT_LT(RotationAngle(camera_T_table.rotation, scene.camera_T_table.rotation), 0.005);
  }
  // Without a calibration the origin is where the optical axis meets the plane: here the table
  // frame's origin, and x is the camera's x.
  const auto plane = EstimateTablePlane(scene.frame, TablePlaneOptions(), std::nullopt, &why);
  const Rigid3 derived = TableFrameOnPlane(*plane, std::nullopt);
  EXPECT_LT((derived.translation - scene.camera_T_table.translation).norm(), 0.005);
  EXPECT_LT(RotationAngle(derived.rotation, scene.camera_T_table.rotation), 0.005);
}

TEST(TablePlaneTest, NoPlaneIsSaid) {
  Scene scene = MakeScene();
  std::string why;
  RgbdFrame empty = scene.frame;
  std::fill(empty.depth.begin(), empty.depth.end(), 0);
  EXPECT_FALSE(EstimateTablePlane(empty, TablePlaneOptions(), std::nullopt, &why));
  EXPECT_THAT(why, HasSubstr("too few valid depth pixels"));
  // A calibration that puts the table 20 cm higher matches no plane.
  Rigid3 wrong = scene.camera_T_table;
  wrong.translation += wrong.rotation * Eigen::Vector3d(0, 0, 0.2);
  EXPECT_FALSE(EstimateTablePlane(scene.frame, TablePlaneOptions(), wrong, &why));
  EXPECT_THAT(why, HasSubstr("within the calibration's tolerance"));
}

}  // namespace
}  // namespace mmh::track
