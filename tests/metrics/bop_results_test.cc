// BOP's result CSV: written and read back (a quarter turn about z and a translation in mm, written
// by hand), the header optional on reading, bad lines named by file, line and field, and the
// scene id of a recording folder.
#include "metrics/bop_results.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::metrics {
namespace {

using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

TEST(BopResultsTest, ReadsAHandWrittenLine) {
  TempDir dir;
  // A quarter turn about z (x -> y), 10 cm to the right, 60 cm ahead; no header.
  WriteText(dir / "r.csv", "48,7,21,0.75,0 -1 0 1 0 0 0 0 1,100 0 600,0.031\n");
  const std::vector<BopResult> r = ReadBopResults(dir / "r.csv");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].scene_id, 48);
  EXPECT_EQ(r[0].im_id, 7);
  EXPECT_EQ(r[0].obj_id, 21);
  EXPECT_EQ(r[0].score, 0.75);
  EXPECT_EQ(r[0].time, 0.031);
  EXPECT_NEAR((r[0].camera_T_object.translation - Eigen::Vector3d(0.1, 0, 0.6)).norm(), 0, 1e-12);
  EXPECT_NEAR((r[0].camera_T_object.rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY())
                  .norm(),
              0, 1e-12);
}

TEST(BopResultsTest, WrittenResultsReadBack) {
  TempDir dir;
  BopResult a;
  a.scene_id = 0;
  a.im_id = 3;
  a.obj_id = 8;
  a.score = 0.5;
  a.camera_T_object = Rigid3(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(-0.03, 0.012, 0.55));
  const std::string text = FormatBopResults({a});
  EXPECT_THAT(text, HasSubstr("scene_id,im_id,obj_id,score,R,t,time\n0,3,8,0.5,"));
  EXPECT_THAT(text, HasSubstr(",-30.000000 12.000000 550.000000,-1\n"));
  WriteText(dir / "r.csv", text);
  const std::vector<BopResult> back = ReadBopResults(dir / "r.csv");
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].obj_id, 8);
  EXPECT_EQ(back[0].time, -1);
  EXPECT_LT(RotationAngle(back[0].camera_T_object.rotation, a.camera_T_object.rotation), 1e-7);
  EXPECT_NEAR((back[0].camera_T_object.translation - a.camera_T_object.translation).norm(), 0,
              1e-9);
}

TEST(BopResultsTest, BadLinesNameTheFileTheLineAndTheField) {
  TempDir dir;
  auto error = [&](const std::string& line) {
    WriteText(dir / "r.csv", "scene_id,im_id,obj_id,score,R,t,time\n" + line + "\n");
    try {
      ReadBopResults(dir / "r.csv");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error("1,2,3,1,1 0 0 0 1 0 0 0 1,0 0 500"), HasSubstr("r.csv:2: 6 fields, expected 7"));
  EXPECT_THAT(error("1,2,x,1,1 0 0 0 1 0 0 0 1,0 0 500,-1"), HasSubstr("r.csv:2: obj_id"));
  EXPECT_THAT(error("1,2,3,1,1 0 0 0 1 0 0 0,0 0 500,-1"), HasSubstr("r.csv:2: R"));
  EXPECT_THAT(error("1,2,3,1,2 0 0 0 1 0 0 0 1,0 0 500,-1"), HasSubstr("a rotation matrix"));
  EXPECT_THAT(error("1,2.5,3,1,1 0 0 0 1 0 0 0 1,0 0 500,-1"), HasSubstr("a non-negative integer"));
}

TEST(BopResultsTest, SceneIdOfAFolderNamedByANumber) {
  EXPECT_EQ(SceneIdOfFolder("data/ycbv/test/000048"), 48);
  EXPECT_EQ(SceneIdOfFolder("data/0000/"), 0);
  EXPECT_EQ(SceneIdOfFolder("take_3"), std::nullopt);
}

}  // namespace
}  // namespace mmh::metrics
