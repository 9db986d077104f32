// The .glb writer against an independent reader and the Khronos glTF-Validator: poses read back
// equal the input to 1e-6, frames convert as docs/notation.md says, bad input writes nothing.
#include "report/gltf_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "montage/layered.h"
#include "report/trajectory_glb.h"
#include "sim/duplo.h"
#include "tests/report/glb_test_util.h"
#include "tools/synthetic_takes.h"

namespace mmh::report {
namespace {

using test_util::AnimatedTrajectory;
using test_util::ParseGlb;

// A wandering trajectory with TUM-like absolute timestamps (1.3e9 s) at 30 Hz.
Trajectory RandomTrajectory(int frames, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> step(0.0, 0.01);
  Trajectory trajectory;
  Eigen::Vector3d position(0.1, -0.05, 0.02);
  Eigen::Quaterniond rotation = Eigen::Quaterniond::UnitRandom();
  for (int i = 0; i < frames; ++i) {
    trajectory.timestamps.push_back(1305031102.175304 + i / 30.0);
    position += Eigen::Vector3d(step(rng), step(rng), step(rng));
    rotation = (rotation * Eigen::Quaterniond(Eigen::AngleAxisd(
                               5 * std::abs(step(rng)),
                               Eigen::Vector3d(step(rng), step(rng), step(rng)).normalized())))
                   .normalized();
    // Random signs: the writer keeps one hemisphere, the comparison must not care.
    if (step(rng) > 0.0) rotation.coeffs() = -rotation.coeffs();
    trajectory.poses.push_back(Rigid3(rotation, position));
  }
  return trajectory;
}

void ExpectSameTrajectory(const Trajectory& expected, const Trajectory& actual, double tolerance) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(expected.timestamps[i], actual.timestamps[i], tolerance) << "frame " << i;
    EXPECT_LE((expected.poses[i].translation - actual.poses[i].translation).cwiseAbs().maxCoeff(),
              tolerance)
        << "frame " << i;
    const Eigen::Vector4d a = expected.poses[i].rotation.coeffs();
    const Eigen::Vector4d b = actual.poses[i].rotation.coeffs();
    EXPECT_LE(std::min((a - b).cwiseAbs().maxCoeff(), (a + b).cwiseAbs().maxCoeff()), tolerance)
        << "frame " << i;
  }
}

// Maps a trajectory read back in glTF's axes into `frame`.
Trajectory FromGltf(Trajectory gltf_T_proxy, TrajectoryFrame frame) {
  const Rigid3 frame_T_gltf = GltfTFrame(frame).Inverse();
  for (Rigid3& pose : gltf_T_proxy.poses) pose = frame_T_gltf * pose;
  return gltf_T_proxy;
}

TEST(GltfFrames, TableZUpBecomesGltfYUp) {
  const Rigid3 gltf_T_table = GltfTFrame(TrajectoryFrame::kTable);
  EXPECT_TRUE((gltf_T_table * Eigen::Vector3d(0, 0, 1)).isApprox(Eigen::Vector3d(0, 1, 0), 1e-15));
  EXPECT_TRUE((gltf_T_table * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(1, 0, 0), 1e-15));
  EXPECT_TRUE((gltf_T_table * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(0, 0, -1), 1e-15));
  // The Kinect camera looks along +z with y down; a glTF camera looks along -z with y up.
  const Rigid3 gltf_T_camera = GltfTFrame(TrajectoryFrame::kCamera);
  EXPECT_TRUE((gltf_T_camera * Eigen::Vector3d(0, 0, 1)).isApprox(Eigen::Vector3d(0, 0, -1), 1e-15));
  EXPECT_TRUE((gltf_T_camera * Eigen::Vector3d(0, 1, 0)).isApprox(Eigen::Vector3d(0, -1, 0), 1e-15));
}

TEST(GltfScene, TrajectoryReadsBackToTheInput) {
  test_util::TempDir dir;
  const Trajectory table_T_proxy = RandomTrajectory(200, 1);
  const TriangleMesh soldier = sim::BuildDuploMesh(sim::SoldierProxy());
  WriteGlb(dir / "soldier.glb", TrajectoryScene(soldier, table_T_proxy, {}));
  const test_util::Glb glb = ParseGlb(test_util::ReadBytes(dir / "soldier.glb"));
  const Trajectory read = FromGltf(AnimatedTrajectory(glb, "proxy", "proxy"), TrajectoryFrame::kTable);
  // 32-bit floats: translations below 1 m and unit quaternions round to < 6e-8; times relative to
  // the first frame (6.6 s) to < 5e-7.
  ExpectSameTrajectory(table_T_proxy, read, 1e-6);

  // One keyframe per frame; the rotation keys keep one hemisphere.
  const auto& animation = glb.json["animations"][0];
  const auto& times = glb.json["accessors"][animation["samplers"][0]["input"].get<int>()];
  EXPECT_EQ(times["count"], 200);
  EXPECT_EQ(times["min"][0], 0.0);
  const Trajectory gltf = AnimatedTrajectory(glb, "proxy", "proxy");
  for (std::size_t i = 1; i < gltf.size(); ++i) {
    EXPECT_GE(gltf.poses[i].rotation.coeffs().dot(gltf.poses[i - 1].rotation.coeffs()), 0.0);
  }

  // The mesh: three vertices per face, unit normals, linear colours of the bricks.
  const auto& primitive = glb.json["meshes"][0]["primitives"][0];
  const auto positions = test_util::AccessorFloats(glb, primitive["attributes"]["POSITION"]);
  const auto normals = test_util::AccessorFloats(glb, primitive["attributes"]["NORMAL"]);
  const auto colors = test_util::AccessorFloats(glb, primitive["attributes"]["COLOR_0"]);
  EXPECT_EQ(positions.size(), 9u * soldier.face_count());
  for (std::size_t v = 0; v < normals.size(); v += 3) {
    ASSERT_NEAR(std::hypot(normals[v], normals[v + 1], normals[v + 2]), 1.0, 1e-6);
  }
  // Face 0's first vertex and colour.
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(positions[c], soldier.vertices(soldier.faces(0, 0), c));
    EXPECT_NEAR(colors[c], SrgbToLinear(soldier.face_colors(0, c)), 1e-7);
  }
  EXPECT_NEAR(SrgbToLinear(255), 1.0, 1e-15);
  EXPECT_NEAR(SrgbToLinear(128), 0.2158605, 1e-6);  // the sRGB standard's curve
  test_util::ExpectValidGltf({dir / "soldier.glb"});
}

// Past 16.8 s float32 keyframe times are off by more than 1e-6 s: the exact times come back from
// the extras, as a frame period (evenly sampled) or a list (uneven); the float times stay the
// keyframes' (to half a unit in the last place).
TEST(GltfScene, LongTracksReadBackTheirTimesExactly) {
  test_util::TempDir dir;
  Trajectory even = RandomTrajectory(3000, 2);  // 100 s at 30 Hz
  Trajectory uneven = even;
  std::mt19937_64 rng(3);
  for (std::size_t i = 1; i < uneven.size(); ++i) {  // sensor jitter of up to 3 ms
    uneven.timestamps[i] += std::uniform_real_distribution<double>(-0.003, 0.003)(rng);
  }
  const TriangleMesh mesh = OrientedStandIn();
  for (const auto& [name, trajectory] : {std::pair{"even", even}, std::pair{"uneven", uneven}}) {
    SCOPED_TRACE(name);
    WriteGlb(dir / (std::string(name) + ".glb"), TrajectoryScene(mesh, trajectory, {.name = name}));
    const test_util::Glb glb = ParseGlb(test_util::ReadBytes(dir / (std::string(name) + ".glb")));
    const auto& extras = glb.json["animations"][0]["extras"];
    EXPECT_EQ(extras.contains("mmh_frame_periods_s"), std::string(name) == "even") << extras.dump().substr(0, 200);
    EXPECT_EQ(extras.contains("mmh_times_s"), std::string(name) == "uneven");
    const Trajectory read = FromGltf(AnimatedTrajectory(glb, name, name), TrajectoryFrame::kTable);
    ExpectSameTrajectory(trajectory, read, 1e-6);
    // The keyframes themselves (what a viewer plays): within half a float ulp of 100 s (3.8e-6).
    const auto times = test_util::AccessorFloats(
        glb, glb.json["animations"][0]["samplers"][0]["input"].get<int>());
    double worst = 0.0;
    for (std::size_t i = 0; i < times.size(); ++i) {
      worst = std::max(worst, std::abs(times[i] - (trajectory.timestamps[i] - trajectory.timestamps[0])));
    }
    EXPECT_GT(worst, 1e-6);  // so the extras are needed
    EXPECT_LE(worst, 3.9e-6);
  }
  // Short tracks (6.6 s) need no extras.
  WriteGlb(dir / "short.glb", TrajectoryScene(mesh, RandomTrajectory(200, 4), {}));
  const test_util::Glb short_glb = ParseGlb(test_util::ReadBytes(dir / "short.glb"));
  const auto& extras = short_glb.json["animations"][0]["extras"];
  EXPECT_FALSE(extras.contains("mmh_frame_periods_s") || extras.contains("mmh_times_s"));
  test_util::ExpectValidGltf({dir / "even.glb", dir / "uneven.glb"});
}

TEST(GltfScene, CameraFrameAndStandIn) {
  test_util::TempDir dir;
  const Trajectory camera_T_proxy = RandomTrajectory(50, 2);
  TrajectoryExportOptions options;
  options.frame = TrajectoryFrame::kCamera;
  options.name = "tracked";
  WriteGlb(dir / "camera.glb", TrajectoryScene(OrientedStandIn(), camera_T_proxy, options));
  const test_util::Glb glb = ParseGlb(test_util::ReadBytes(dir / "camera.glb"));
  ExpectSameTrajectory(camera_T_proxy,
                       FromGltf(AnimatedTrajectory(glb, "tracked", "tracked"), TrajectoryFrame::kCamera),
                       1e-6);
  EXPECT_TRUE(IsClosed(OrientedStandIn()) || OrientedStandIn().face_count() == 48);
  test_util::ExpectValidGltf({dir / "camera.glb"});
}

TEST(GltfScene, BadInputWritesNothing) {
  test_util::TempDir dir;
  const TriangleMesh mesh = OrientedStandIn();
  Trajectory nan = RandomTrajectory(10, 3);
  nan.poses[4].translation.y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(test_util::ErrorOf([&] { WriteGlb(dir / "a.glb", TrajectoryScene(mesh, nan, {})); })
                .find("proxy"),
            std::string::npos);
  Trajectory stretched = RandomTrajectory(10, 3);
  stretched.poses[2].rotation.coeffs() *= 1.001;
  EXPECT_NE(test_util::ErrorOf([&] { WriteGlb(dir / "b.glb", TrajectoryScene(mesh, stretched, {})); })
                .find("quaternion"),
            std::string::npos);
  // Timestamps that collapse as 32-bit floats after the time origin.
  Trajectory dense = RandomTrajectory(3, 4);
  dense.timestamps = {0.0, 1000.0, 1000.00000001};
  EXPECT_NE(test_util::ErrorOf([&] { WriteGlb(dir / "c.glb", TrajectoryScene(mesh, dense, {})); })
                .find("32-bit"),
            std::string::npos);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(MontageScene, TakesWarpedAndRecordedMarkersAndLayers) {
  test_util::TempDir dir;
  synthetic::TakeSetOptions takes;
  takes.takes = 3;
  takes.reference_frames = 240;
  takes.min_frames = 220;
  takes.max_frames = 260;
  const synthetic::TakeSet first = synthetic::MakeTakeSet(takes);
  takes.min_frames = takes.max_frames = 240;
  takes.seed = 9;
  const synthetic::TakeSet second = synthetic::MakeTakeSet(takes);
  montage::ComposeOptions options;
  options.labelling.min_segment_length = 30;
  const auto montages = montage::ComposeLayered(
      {{"mario", first.takes, first.annotations}, {"monster", second.takes, second.annotations}},
      options);

  std::vector<MontageObject> objects(2);
  for (int o = 0; o < 2; ++o) {
    objects[o].name = o == 0 ? "mario" : "monster";
    objects[o].mesh = o == 0 ? sim::BuildDuploMesh(sim::SoldierProxy()) : OrientedStandIn();
    objects[o].montage = montages[o].trajectory;
    objects[o].takes = o == 0 ? first.takes : second.takes;
    objects[o].warps = montages[o].warps;
  }
  objects[0].marker_frames = {10, 100};
  WriteGlb(dir / "montage.glb", MontageScene(objects));
  const test_util::Glb glb = ParseGlb(test_util::ReadBytes(dir / "montage.glb"));

  for (int o = 0; o < 2; ++o) {
    const std::string& name = objects[o].name;
    ExpectSameTrajectory(objects[o].montage,
                         FromGltf(AnimatedTrajectory(glb, "montage", name + " montage"),
                                  TrajectoryFrame::kTable),
                         1e-6);
    for (int k = 0; k < 3; ++k) {
      const std::string take = name + " take " + std::to_string(k + 1);
      const Trajectory& reference = objects[o].takes[0];
      Trajectory warped;
      warped.timestamps = reference.timestamps;
      for (int w : objects[o].warps[k]) warped.poses.push_back(objects[o].takes[k].poses[w]);
      ExpectSameTrajectory(
          warped, FromGltf(AnimatedTrajectory(glb, "montage", take + " warped"), TrajectoryFrame::kTable),
          1e-6);
      ExpectSameTrajectory(
          objects[o].takes[k],
          FromGltf(AnimatedTrajectory(glb, "montage", take + " recorded"), TrajectoryFrame::kTable),
          1e-6);
    }
  }
  // Markers: grey static copies at the montage's poses.
  for (int frame : objects[0].marker_frames) {
    const std::string name = "mario marker at frame " + std::to_string(frame);
    const Rigid3 table_T_marker =
        GltfTFrame(TrajectoryFrame::kTable).Inverse() * test_util::NodePose(glb, name);
    EXPECT_LE((table_T_marker.translation - objects[0].montage.poses[frame].translation).norm(), 1e-12);
    EXPECT_NEAR(RotationAngle(table_T_marker.rotation, objects[0].montage.poses[frame].rotation), 0.0,
                1e-7);
    const int mesh = glb.json["nodes"][test_util::NodeIndex(glb, name)]["mesh"];
    const auto& primitive = glb.json["meshes"][mesh]["primitives"][0];
    EXPECT_FALSE(primitive["attributes"].contains("COLOR_0"));
    EXPECT_EQ(glb.json["materials"][primitive["material"].get<int>()]["name"], "spatial marker");
  }
  test_util::ExpectValidGltf({dir / "montage.glb"});

  objects[0].marker_frames = {10, 100000};
  EXPECT_NE(test_util::ErrorOf([&] { MontageScene(objects); }).find("100000"), std::string::npos);
}

}  // namespace
}  // namespace mmh::report
