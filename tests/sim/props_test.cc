// Tests of sim/props.h: the table scene's objects and options, the slider block's pose in the Like
// box and its inverse, the hand in its grip frame.
#include "sim/props.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>

#include "core/error.h"
#include "core/options.h"
#include "sim/duplo.h"

namespace mmh::sim {
namespace {

using ::testing::HasSubstr;

std::map<std::string, TriangleMesh> SceneByName(const TableSceneOptions& options) {
  std::map<std::string, TriangleMesh> meshes;
  for (NamedMesh& named : BuildTableScene(options)) {
    EXPECT_FALSE(meshes.count(named.name)) << named.name;
    meshes[named.name] = std::move(named.mesh);
  }
  return meshes;
}

TEST(TableSceneTest, DefaultSceneHasTheTableTopAtZeroAndTheTapes) {
  const TableSceneOptions options;
  const auto scene = SceneByName(options);
  for (const char* name : {"floor", "table", "play_area_tape", "like_box_tape", "backdrop"}) {
    ASSERT_TRUE(scene.count(name)) << name;
    EXPECT_NO_THROW(ValidateMesh(scene.at(name), name));
    EXPECT_TRUE(IsClosed(scene.at(name))) << name;
    EXPECT_GT(SignedVolume(scene.at(name)), 0) << name;
  }
  EXPECT_FALSE(scene.count("castle"));

  const Bounds3 table = ComputeBounds(scene.at("table"));
  EXPECT_NEAR(table.max.z(), 0.0, 1e-9);
  EXPECT_NEAR(table.min.z(), -0.75, 1e-6);  // the legs reach the floor
  EXPECT_NEAR(table.max.x() - table.min.x(), 1.2, 1e-6);
  EXPECT_NEAR(table.max.y() - table.min.y(), 0.8, 1e-6);
  // Table top volume plus four 5 x 5 cm legs.
  EXPECT_NEAR(SignedVolume(scene.at("table")), 1.2 * 0.8 * 0.03 + 4 * 0.05 * 0.05 * 0.72, 1e-6);

  // Play area tape: outside the 0.40 x 0.30 m rectangle, 1 mm thick on the table top.
  const TriangleMesh& tape = scene.at("play_area_tape");
  const Bounds3 t = ComputeBounds(tape);
  EXPECT_NEAR(t.min.x(), -0.2 - 0.006, 1e-6);
  EXPECT_NEAR(t.max.y(), 0.15 + 0.006, 1e-6);
  EXPECT_NEAR(t.min.z(), 0.0, 1e-9);
  EXPECT_NEAR(t.max.z(), 0.001, 1e-7);
  const double outer = (0.4 + 0.012) * (0.3 + 0.012);
  EXPECT_NEAR(SignedVolume(tape), (outer - 0.4 * 0.3) * 0.001, 1e-9);

  const Bounds3 like = ComputeBounds(scene.at("like_box_tape"));
  EXPECT_NEAR(0.5 * (like.min.x() + like.max.x()), 0.36, 1e-6);
  EXPECT_NEAR(0.5 * (like.min.y() + like.max.y()), -0.05, 1e-6);
  EXPECT_NEAR(like.max.x() - like.min.x(), 0.16 + 0.012, 1e-6);

  const Bounds3 wall = ComputeBounds(scene.at("backdrop"));
  EXPECT_NEAR(wall.min.y(), 0.5, 1e-6);
  EXPECT_GT(wall.max.z(), 0.75);  // above the camera
}

TEST(TableSceneTest, CastleStandsBehindThePlayArea) {
  TableSceneOptions options;
  options.props = TableProps::kCastle;
  options.backdrop = false;
  const auto scene = SceneByName(options);
  EXPECT_FALSE(scene.count("backdrop"));
  ASSERT_TRUE(scene.count("castle"));
  const TriangleMesh& castle = scene.at("castle");
  EXPECT_TRUE(IsClosed(castle));
  EXPECT_GT(SignedVolume(castle), 0);
  const Bounds3 b = ComputeBounds(castle);
  EXPECT_GT(b.min.y(), 0.15 + 0.006);  // behind the play area and its tape
  EXPECT_LE(b.max.y(), 0.4);           // on the table
  EXPECT_NEAR(b.min.z(), 0.0, 1e-9);
  EXPECT_GE(b.max.z(), 0.2);
  EXPECT_LE(b.max.z(), 0.3);
  EXPECT_NEAR(b.max.x() - b.min.x(), 0.3, 0.05);
  EXPECT_GT(castle.face_count(), 300);
  EXPECT_LT(castle.face_count(), 2000);
}

TEST(TableSceneTest, OptionsReadFromJsonByName) {
  TableSceneOptions options;
  FromJson(nlohmann::json::parse(R"({"props": "castle", "table_width": 1.5})"), "scene",
           ConfigSource{"test"}, &options);
  EXPECT_EQ(options.props, TableProps::kCastle);
  EXPECT_EQ(options.table_width, 1.5);
  EXPECT_EQ(ToJson(options)["props"], "castle");
  try {
    FromJson(nlohmann::json::parse(R"({"props": "tower"})"), "scene", ConfigSource{"test"},
             &options);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scene.props"));
    EXPECT_THAT(e.what(), HasSubstr("none, castle"));
  }
}

std::string ValidateError(const TableSceneOptions& options) {
  try {
    options.Validate("scene");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

TEST(TableSceneTest, ValidateNamesTheFieldAndValue) {
  TableSceneOptions o;
  o.table_width = -1;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.table_width: got -1"));
  o = {};
  o.like_box_length = 0.03;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.like_box_length: got 0.03"));
  o = {};
  o.like_box_center_x = 0.58;  // off the table's right edge
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.like_box_center_x: got 0.58"));
  o = {};
  o.like_box_center_x = 0.1;  // on the play area
  EXPECT_THAT(ValidateError(o), HasSubstr("clear of the play area"));
  o = {};
  o.play_area_depth = 0.9;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.play_area_depth: got 0.9"));
  o = {};
  o.backdrop_y = 0.2;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.backdrop_y: got 0.2"));
  o = {};
  o.table_depth = 0.6;
  o.props = TableProps::kCastle;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.props"));
  o = {};
  o.tape_width = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.tape_width: got nan"));
  EXPECT_NO_THROW(TableSceneOptions{}.Validate("scene"));
}

// A real scene's desk (the views of tests/data/real/ycbv): the top moved and turned, no tape.
TEST(TableSceneTest, TableTopMovedAndTurnedWithoutTape) {
  TableSceneOptions o;
  o.table_x = 0.2;
  o.table_y = 0.4;
  o.table_yaw_deg = -30;
  o.table_width = 2.0;
  o.table_depth = 1.2;
  o.tape_thickness = 0;
  o.play_area_width = o.play_area_depth = 0.1;
  o.backdrop = false;
  const auto scene = SceneByName(o);
  EXPECT_FALSE(scene.count("play_area_tape"));
  EXPECT_FALSE(scene.count("like_box_tape"));
  const TriangleMesh& table = scene.at("table");
  EXPECT_TRUE(IsClosed(table));
  EXPECT_NEAR(SignedVolume(table), 2.0 * 1.2 * 0.03 + 4 * 0.05 * 0.05 * 0.72, 1e-5);
  // The front edge's middle is 0.6 m from the centre along the top's -y, its y axis turned by
  // -30 deg: (0.2, 0.4) - 0.6 (-sin(-30), cos(-30)) = (-0.1, -0.1196); the top's corners are
  // its extremes in x and y.
  const double c = std::cos(-30 * M_PI / 180), s = std::sin(-30 * M_PI / 180);
  double min_y = 1e9, max_x = -1e9;
  for (const double x : {-1.0, 1.0}) {
    for (const double y : {-0.6, 0.6}) {
      min_y = std::min(min_y, 0.4 + s * x + c * y);
      max_x = std::max(max_x, 0.2 + c * x - s * y);
    }
  }
  const Bounds3 b = ComputeBounds(table);
  EXPECT_NEAR(b.min.y(), min_y, 1e-6);
  EXPECT_NEAR(b.max.x(), max_x, 1e-6);
  EXPECT_NEAR(b.max.z(), 0.0, 1e-9);
  const Eigen::Vector3d front = o.TableTTop() * Eigen::Vector3d(0, -0.6, 0);
  EXPECT_NEAR(front.x(), -0.1, 1e-9);
  EXPECT_NEAR(front.y(), 0.4 - 0.6 * c, 1e-9);

  // A play area that reaches over the turned top's front edge (its middle at (-0.1, 0.03))
  // names the key and the turn.
  o.table_y = 0.55;
  o.play_area_width = o.play_area_depth = 0.3;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.play_area_"));
  EXPECT_THAT(ValidateError(o), HasSubstr("turned -30 deg"));
  o.table_y = 0.4;
  o.play_area_width = o.play_area_depth = 0.1;
  o.backdrop = true;
  o.backdrop_y = 0.9;  // in front of the far corner, 0.4 + 0.5 + 0.52
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.backdrop_y: got 0.9"));
  EXPECT_THAT(ValidateError(o), HasSubstr("the table's far corner"));
  o.backdrop = false;
  o.table_yaw_deg = 200;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.table_yaw_deg: got 200"));
  o.table_yaw_deg = 0;
  o.table_x = std::numeric_limits<double>::infinity();
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.table_x: got inf"));
  o.table_x = 0;
  o.tape_thickness = -0.001;
  EXPECT_THAT(ValidateError(o), HasSubstr("scene.tape_thickness: got -0.001"));
}

TEST(TableSceneTest, ObjectsAreReadFromJsonAndValidated) {
  TableSceneOptions options;
  FromJson(nlohmann::json::parse(R"({"objects": [
             {"name": "mug", "mesh": "mug.obj", "x": 0.1, "qz": 0.6, "qw": 0.8,
              "material": {"ir_albedo": 0.6, "specularity": 0.3}},
             {"name": "brick", "mesh": "brick.obj", "scale": 0.001}]})"),
           "scene", ConfigSource{"test"}, &options);
  ASSERT_EQ(options.objects.size(), 2u);
  EXPECT_EQ(options.objects[0].material.specularity, 0.3);
  EXPECT_EQ(options.objects[1].scale, 0.001);
  EXPECT_EQ(options.objects[1].material.ir_albedo, 0.5);
  EXPECT_NO_THROW(options.Validate("scene"));
  const Rigid3 table_T_mug = options.objects[0].TableTObject();
  EXPECT_NEAR(
      (table_T_mug * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0.1 + 0.28, 0.96, 0)).norm(), 0.0,
      1e-12);  // a turn of 2 atan(0.6 / 0.8) = 73.7 deg about z
  EXPECT_EQ(ToJson(options)["objects"][1]["name"], "brick");
  auto expect_error = [&](auto change, const std::string& message) {
    TableSceneOptions o = options;
    change(o);
    EXPECT_THAT(ValidateError(o), HasSubstr(message));
  };
  expect_error([](auto& o) { o.objects[1].name = "mug"; }, "scene.objects[1].name: got \"mug\"");
  expect_error([](auto& o) { o.objects[0].name = "table"; },
               "scene.objects[0].name: got \"table\"");
  expect_error([](auto& o) { o.objects[0].name = ""; }, "scene.objects[0].name");
  expect_error([](auto& o) { o.objects[1].mesh = ""; }, "scene.objects[1].mesh");
  expect_error([](auto& o) { o.objects[0].qw = 0.9; }, "scene.objects[0].qx, qy, qz, qw");
  expect_error([](auto& o) { o.objects[0].z = std::numeric_limits<double>::infinity(); },
               "scene.objects[0].z: got inf");
  expect_error([](auto& o) { o.objects[1].scale = 0; }, "scene.objects[1].scale: got 0");
  expect_error([](auto& o) { o.objects[0].material.ir_albedo = 2; },
               "scene.objects[0].material.ir_albedo");
}

TEST(SliderTest, EndsOfTheScaleTouchTheEndsOfTheBox) {
  const TableSceneOptions options;
  const Rigid3 dislike = LikeBoxSliderPose(options, -5.0);
  const Rigid3 like = LikeBoxSliderPose(options, 5.0);
  const Rigid3 neutral = LikeBoxSliderPose(options, 0.0);
  const double half_block = 0.5 * kSliderBlockSize;
  EXPECT_NEAR(dislike.translation.x() - half_block, 0.36 - 0.08, 1e-12);  // left end
  EXPECT_NEAR(like.translation.x() + half_block, 0.36 + 0.08, 1e-12);     // right end
  EXPECT_NEAR(neutral.translation.x(), 0.36, 1e-12);
  for (const Rigid3& pose : {dislike, like, neutral}) {
    EXPECT_NEAR(pose.translation.y(), -0.05, 1e-12);
    EXPECT_EQ(pose.translation.z(), 0.0);
    EXPECT_NEAR(pose.rotation.angularDistance(Eigen::Quaterniond::Identity()), 0.0, 1e-12);
  }
  // The block in the box, its bottom on the table.
  const Bounds3 block = ComputeBounds(Transformed(BuildSliderBlock(), like));
  EXPECT_NEAR(block.max.x(), 0.44, 1e-6);
  EXPECT_NEAR(block.min.z(), 0.0, 1e-9);
  EXPECT_GT(block.min.y(), -0.05 - 0.03);
  EXPECT_LT(block.max.y(), -0.05 + 0.03);
}

TEST(SliderTest, PositionToValueInvertsThePose) {
  TableSceneOptions options;
  options.like_box_center_x = -0.4;
  options.like_box_length = 0.2;
  for (double value = -5.0; value <= 5.0; value += 0.25) {
    const Rigid3 pose = LikeBoxSliderPose(options, value);
    EXPECT_NEAR(SliderValueFromPosition(options, pose.translation), value, 1e-9);
  }
  // Beyond the ends: not clamped.
  EXPECT_GT(SliderValueFromPosition(options, {0.0, 0.0, 0.0}), 5.0);
}

TEST(SliderTest, OutOfRangeValuesAreInputErrors) {
  const TableSceneOptions options;
  for (const double bad : {-5.01, 5.5, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      LikeBoxSliderPose(options, bad);
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("slider value"));
      EXPECT_THAT(e.what(), HasSubstr("[-5, 5]"));
    }
  }
}

TEST(SliderTest, BlockIsAGreenTwoByTwoBrick) {
  const TriangleMesh block = BuildSliderBlock();
  const Bounds3 b = ComputeBounds(block);
  EXPECT_NEAR(b.max.x() - b.min.x(), kSliderBlockSize, 1e-7);
  EXPECT_NEAR(b.max.y() - b.min.y(), kSliderBlockSize, 1e-7);
  for (int f = 0; f < block.face_count(); ++f) {
    EXPECT_EQ(block.face_colors(f, 0), kDuploGreen[0]);
    EXPECT_EQ(block.face_colors(f, 1), kDuploGreen[1]);
  }
}

// Points on the hand's surface: a grid of barycentric samples on every face.
std::vector<Eigen::Vector3d> SurfaceSamples(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> samples;
  constexpr int kSteps = 8;
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2)).cast<double>();
    for (int i = 0; i <= kSteps; ++i) {
      for (int j = 0; i + j <= kSteps; ++j) {
        const double wb = static_cast<double>(i) / kSteps;
        const double wc = static_cast<double>(j) / kSteps;
        samples.push_back(a + wb * (b - a) + wc * (c - a));
      }
    }
  }
  return samples;
}

// Checks the pinch of a hand built with `options`: the finger pads touch the front plane
// y = -grip / 2 and the thumb the back plane y = +grip / 2 a centimetre or so below the grasp
// point, and nothing of the hand enters the proxy's volume between them below the origin.
void ExpectPinch(const HandOptions& options) {
  const TriangleMesh hand = BuildHandAndForearm(options);
  const double half = 0.5 * options.grip_width;
  bool front_touch = false;
  bool back_touch = false;
  int inside = 0;
  for (const Eigen::Vector3d& p : SurfaceSamples(hand)) {
    const bool pinch_height = p.z() < -0.005 && p.z() > -0.02;
    front_touch = front_touch || (pinch_height && std::abs(p.x()) < 0.02 && p.y() < -half &&
                                  p.y() > -half - 0.002);
    back_touch = back_touch ||
                 (pinch_height && std::abs(p.x()) < 0.02 && p.y() > half && p.y() < half + 0.002);
    if (std::abs(p.x()) < 0.016 && std::abs(p.y()) < half - 0.0005 && p.z() < -0.0005 &&
        p.z() > -0.05) {
      ++inside;
    }
  }
  EXPECT_TRUE(front_touch) << "no finger pad on the front face";
  EXPECT_TRUE(back_touch) << "no thumb pad on the back face";
  EXPECT_EQ(inside, 0) << "surface points inside the grasped proxy";
}

TEST(HandTest, HandPinchesFromAboveAndTheForearmRisesAway) {
  const HandOptions options;
  const TriangleMesh hand = BuildHandAndForearm(options);
  EXPECT_NO_THROW(ValidateMesh(hand, "hand"));
  EXPECT_TRUE(IsClosed(hand));  // a union of closed parts
  EXPECT_GT(SignedVolume(hand), 0);
  EXPECT_GT(hand.face_count(), 500);
  EXPECT_LT(hand.face_count(), 2500);
  for (int f = 0; f < hand.face_count(); ++f) {
    EXPECT_EQ(hand.face_colors(f, 0), kSkinColor[0]);
  }
  const Bounds3 b = ComputeBounds(hand);
  // The forearm's far end: up and away from the camera.
  EXPECT_GT(b.max.y(), 0.25);
  EXPECT_GT(b.max.z(), 0.2);
  // The hand comes down only a little below the grasp point and not far in front of it.
  EXPECT_LT(b.min.z(), -0.01);
  EXPECT_GT(b.min.z(), -0.04);
  EXPECT_LT(b.min.y(), -0.016);
  EXPECT_GT(b.min.y(), -0.06);
  // About a hand's width across x, the thumb on +x.
  EXPECT_GT(b.max.x() - b.min.x(), 0.07);
  EXPECT_LT(b.max.x() - b.min.x(), 0.14);
  EXPECT_GT(b.max.x(), -b.min.x());
  ExpectPinch(options);
}

TEST(HandTest, PinchFollowsGripWidthCurlAndScale) {
  for (const double grip : {0.016, 0.0318, 0.048}) {
    HandOptions options;
    options.grip_width = grip;
    SCOPED_TRACE(grip);
    ExpectPinch(options);
  }
  HandOptions curled;
  curled.finger_curl = 0.7;
  ExpectPinch(curled);
  HandOptions big;
  big.scale = 1.2;
  ExpectPinch(big);
  const Bounds3 a = ComputeBounds(BuildHandAndForearm(HandOptions{}));
  const Bounds3 b = ComputeBounds(BuildHandAndForearm(big));
  EXPECT_NEAR(b.max.x() - b.min.x(), 1.2 * (a.max.x() - a.min.x()), 0.01);
}

TEST(HandTest, OptionsAreValidated) {
  HandOptions bad;
  bad.finger_curl = 2.0;
  try {
    BuildHandAndForearm(bad);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("hand.finger_curl: got 2"));
  }
  bad = {};
  bad.segments = 2;
  EXPECT_THROW(bad.Validate("hand"), InputError);
  bad = {};
  bad.grip_width = 0.2;
  EXPECT_THROW(bad.Validate("hand"), InputError);
  EXPECT_NO_THROW(HandOptions{}.Validate("hand"));
}

}  // namespace
}  // namespace mmh::sim
