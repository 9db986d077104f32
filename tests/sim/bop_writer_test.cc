// Tests of sim/bop_writer.h: the JSON parses back to the poses and intrinsics that were written.
#include "sim/bop_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::sim {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test_util::ErrorOf;
using test_util::ReadBytes;
using test_util::TempDir;

TEST(BopWriterTest, JsonParsesBackToThePoses) {
  TempDir dir;
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  BopFrames frames(12);
  for (size_t i = 0; i < frames.size(); ++i) {
    // Frame 3 sees no object; the others one or two.
    const int objects = i == 3 ? 0 : 1 + static_cast<int>(i % 2);
    for (int k = 0; k < objects; ++k) {
      Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
      q.normalize();
      frames[i].push_back({k + 1, Rigid3(q, Eigen::Vector3d(normal(rng), normal(rng),
                                                            1.0 + std::abs(normal(rng))))});
    }
  }
  PinholeIntrinsics intrinsics;
  intrinsics.fx = 525.125;
  intrinsics.cy = 239.75;
  WriteBopScene(dir / "000001", frames, intrinsics);

  const auto gt = nlohmann::json::parse(ReadBytes(dir / "000001" / "scene_gt.json"));
  ASSERT_EQ(gt.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& image = gt.at(std::to_string(i));
    ASSERT_EQ(image.size(), frames[i].size()) << i;
    for (size_t k = 0; k < frames[i].size(); ++k) {
      const auto& object = image[k];
      EXPECT_EQ(object["obj_id"].get<int>(), frames[i][k].obj_id);
      const Eigen::Matrix3d expected =
          frames[i][k].camera_T_object.rotation.normalized().toRotationMatrix();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          // Round-trip digits: the parsed number is the written double.
          EXPECT_EQ(object["cam_R_m2c"][3 * r + c].get<double>(), expected(r, c));
        }
      }
      const Eigen::Vector3d t = frames[i][k].camera_T_object.translation;
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(object["cam_t_m2c"][a].get<double>(), 1000.0 * t[a]);  // millimetres
      }
    }
  }
  const auto camera = nlohmann::json::parse(ReadBytes(dir / "000001" / "scene_camera.json"));
  ASSERT_EQ(camera.size(), frames.size());
  EXPECT_EQ(camera["11"]["cam_K"],
            nlohmann::json({525.125, 0.0, 319.5, 0.0, 525.0, 239.75, 0.0, 0.0, 1.0}));
  EXPECT_EQ(camera["0"]["depth_scale"].get<double>(), 0.2);
  // Keys in increasing image id, one image per line.
  const std::string text = ReadBytes(dir / "000001" / "scene_gt.json");
  EXPECT_LT(text.find("\"9\""), text.find("\"10\""));
  EXPECT_THAT(text, HasSubstr("\n  \"3\": [],\n"));
}

TEST(BopWriterTest, ChecksInput) {
  TempDir dir;
  BopFrames frames(2);
  frames[1].push_back({0, Rigid3()});
  EXPECT_THAT(ErrorOf([&] { WriteBopSceneGt(dir / "gt.json", frames); }),
              HasSubstr("image 1, object 0, obj_id: got 0, expected a BOP object id >= 1"));
  frames[1][0] = {1, Rigid3(Eigen::Quaterniond(2, 0, 0, 0), Eigen::Vector3d::Zero())};
  EXPECT_THAT(ErrorOf([&] { WriteBopSceneGt(dir / "gt.json", frames); }),
              HasSubstr("rotation norm: got 2"));
  EXPECT_FALSE(fs::exists(dir / "gt.json"));
  PinholeIntrinsics bad;
  bad.fx = -1;
  EXPECT_THAT(ErrorOf([&] { WriteBopSceneCamera(dir / "cam.json", bad, 3); }), HasSubstr("fx"));
  EXPECT_THAT(ErrorOf([&] { WriteBopSceneCamera(dir / "cam.json", PinholeIntrinsics(), 3, 0.0); }),
              HasSubstr("depth_scale: got 0"));
}

}  // namespace
}  // namespace mmh::sim
