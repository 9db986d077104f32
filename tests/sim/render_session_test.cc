// Tests of sim/render_session.h's TableTopScene: the user's static objects (scene.objects) are
// loaded from their files, placed by their pose and seen by the sensor.
#include "sim/render_session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "sim/kinect_sensor.h"
#include "sim/primitives.h"
#include "sim/sensor_check.h"
#include "tests/test_util.h"

namespace mmh::sim {
namespace {

using test_util::TempDir;
using ::testing::HasSubstr;

constexpr double kCube = 0.1;  // [m]

// A 10 cm cube standing on the table at (0.25, 0.1), turned `yaw` about the table's normal.
SceneObject Cube(const std::string& mesh, double yaw) {
  SceneObject cube;
  cube.name = "cube";
  cube.mesh = mesh;
  cube.x = 0.25;
  cube.y = 0.1;
  cube.z = kCube / 2;
  cube.qz = std::sin(yaw / 2);
  cube.qw = std::cos(yaw / 2);
  return cube;
}

// The exact depth [m] at the pixel where the table point `table_p` projects, and that point's own
// depth in the depth camera.
struct DepthAt {
  double rendered = 0.0;
  double expected = 0.0;
};

std::vector<DepthAt> ExactDepthAt(const RenderConfig& config,
                                  const std::vector<Eigen::Vector3d>& table_points) {
  TableTopScene scene(config, MakeBox({0.02, 0.02, 0.02}, {200, 0, 0}));
  scene.SetFrame(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -10)), 0.0);
  KinectSensorOptions options = config.sensor;
  options.mode = SensorMode::kStatistical;
  options.noise = false;
  options.quantise = false;
  KinectSensor sensor(options, &scene.scene(), scene.table_T_camera());
  const RgbdFrame frame = sensor.Render(0);
  const std::vector<float> depth = DepthMetresFromUnits(frame.depth, frame.depth_scale);
  const Rigid3 camera_T_table = sensor.world_T_depth_camera().Inverse();
  std::vector<DepthAt> result;
  for (const Eigen::Vector3d& p : table_points) {
    const Eigen::Vector3d camera_p = camera_T_table * p;
    const Eigen::Vector2d uv = frame.depth_intrinsics.Project(camera_p);
    const int u = static_cast<int>(std::lround(uv.x()));
    const int v = static_cast<int>(std::lround(uv.y()));
    EXPECT_TRUE(u >= 0 && v >= 0 && u < frame.depth_intrinsics.width &&
                v < frame.depth_intrinsics.height);
    result.push_back(
        {depth[static_cast<size_t>(v) * frame.depth_intrinsics.width + u], camera_p.z()});
  }
  return result;
}

TEST(TableTopSceneTest, SceneObjectsAreLoadedPlacedAndSeen) {
  TempDir dir;
  const std::string mesh = (dir.path() / "cube.ply").string();
  WritePly(MakeBox({kCube, kCube, kCube}, {90, 90, 200}), mesh);
  // The top face's centre, and a point 6 cm along x from it: beyond the upright cube's half width
  // (5 cm), within the turned cube's half diagonal (7.07 cm).
  const std::vector<Eigen::Vector3d> points = {{0.25, 0.1, kCube}, {0.31, 0.1, kCube}};
  RenderConfig config;
  config.scene.objects = {Cube(mesh, 0.0)};
  const std::vector<DepthAt> upright = ExactDepthAt(config, points);
  EXPECT_NEAR(upright[0].rendered, upright[0].expected, 0.002);
  EXPECT_GT(upright[1].rendered, upright[1].expected + 0.01);  // the table behind the cube
  config.scene.objects = {Cube(mesh, std::numbers::pi / 4)};
  const std::vector<DepthAt> turned = ExactDepthAt(config, points);
  EXPECT_NEAR(turned[0].rendered, turned[0].expected, 0.002);
  EXPECT_NEAR(turned[1].rendered, turned[1].expected, 0.002);
  config.scene.objects.clear();
  const std::vector<DepthAt> without = ExactDepthAt(config, points);
  EXPECT_GT(without[0].rendered, without[0].expected + 0.05);  // the table top, 10 cm lower
}

// The camera's roll turns the image about the viewing axis: the look-at point stays on it, the
// image x axis (horizontal without roll) turns towards the image y by the roll.
TEST(RenderConfigTest, CameraRollTurnsTheImageAboutTheViewingAxis) {
  CameraPlacement camera;  // (0, -0.65, 0.55) looking at the origin
  const Rigid3 level = camera.TableTCamera();
  EXPECT_NEAR(level.rotation.toRotationMatrix().col(0).z(), 0.0, 1e-12);  // x horizontal
  camera.roll_deg = 30;
  const Rigid3 rolled = camera.TableTCamera();
  const Eigen::Matrix3d r0 = level.rotation.toRotationMatrix();
  const Eigen::Matrix3d r = rolled.rotation.toRotationMatrix();
  EXPECT_LT((r.col(2) - r0.col(2)).norm(), 1e-12);  // the same viewing axis
  const double c = std::cos(std::numbers::pi / 6), s = std::sin(std::numbers::pi / 6);
  EXPECT_LT((r.col(0) - (c * r0.col(0) + s * r0.col(1))).norm(), 1e-12);
  EXPECT_LT((r.col(1) - (-s * r0.col(0) + c * r0.col(1))).norm(), 1e-12);
  // The origin, looked at, stays at the image centre; a point right of it in the level image is
  // seen turned back by the roll (up, towards -y) in the rolled one.
  const Eigen::Vector3d centre = rolled.Inverse() * Eigen::Vector3d::Zero();
  EXPECT_NEAR(centre.x(), 0.0, 1e-12);
  EXPECT_NEAR(centre.y(), 0.0, 1e-12);
  const Eigen::Vector3d right = level * Eigen::Vector3d(0.1, 0, 0.85);
  const Eigen::Vector3d seen = rolled.Inverse() * right;
  EXPECT_NEAR(seen.x(), 0.1 * c, 1e-12);
  EXPECT_NEAR(seen.y(), -0.1 * s, 1e-12);
  camera.roll_deg = 200;
  try {
    camera.Validate("camera");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera.roll_deg: got 200"));
  }
}

TEST(RenderConfigTest, ObjectMeshesAreRelativeToTheirConfigFile) {
  TempDir dir;
  std::filesystem::create_directories(dir / "views");
  {
    std::ofstream file(dir / "views" / "view.json");
    file << R"({"scene": {"objects": [{"name": "cube", "mesh": "../models/cube.ply"},
                                        {"name": "far", "mesh": "/abs/far.ply"}]}})";
  }
  Config config = Config::Load(dir / "views" / "view.json");
  const RenderConfig from_file = RenderConfig::FromConfig(config);
  EXPECT_EQ(from_file.scene.objects[0].mesh, (dir / "models" / "cube.ply").string());
  EXPECT_EQ(from_file.scene.objects[1].mesh, "/abs/far.ply");
  config.Set(R"(scene.objects=[{"name": "cube", "mesh": "models/cube.ply"}])");
  EXPECT_EQ(RenderConfig::FromConfig(config).scene.objects[0].mesh, "models/cube.ply");  // cwd
}

TEST(TableTopSceneTest, AMissingMeshNamesTheObjectsKey) {
  TempDir dir;
  RenderConfig config;
  config.scene.objects = {Cube((dir.path() / "nowhere.obj").string(), 0.0)};
  try {
    TableTopScene scene(config, MakeBox({0.02, 0.02, 0.02}, {200, 0, 0}));
    FAIL() << "accepted a missing mesh";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scene.objects[0].mesh (cube)"));
    EXPECT_THAT(e.what(), HasSubstr("nowhere.obj"));
  }
}

}  // namespace
}  // namespace mmh::sim
