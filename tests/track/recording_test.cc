// Readers of real recordings with ground truth: the committed YCB-Video frames, the same frames
// converted here into a BOP scene (from the raw MAT arrays, so both readers are checked against
// the file's numbers, not against each other's code), and bad ground truth (InputError naming
// the file, the image and the value).
#include "track/recording.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "track/mat_file.h"
#include "tests/test_util.h"

namespace mmh::track {
namespace {

namespace fs = std::filesystem;
using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

const fs::path kYcb = fs::path(MMH_TEST_DATA_DIR) / "real" / "ycbv" / "data" / "0000";

TEST(RecordingTest, ReadsYcbVideoFrames) {
  ASSERT_EQ(DetectRecordingLayout(kYcb), RecordingLayout::kYcbVideo);
  RecordingFrameSource source(kYcb);
  ASSERT_EQ(source.size(), 10);
  EXPECT_EQ(source.object_ids(), (std::vector<int>{8, 14, 21}));
  const RecordingFrameInfo& first = source.frames()[0];
  EXPECT_EQ(first.image_id, 1);
  EXPECT_DOUBLE_EQ(first.depth_scale, 1e-4);  // factor_depth 10000
  EXPECT_NEAR(first.intrinsics.fx, 1066.778, 1e-3);
  EXPECT_NEAR(first.intrinsics.cy, 241.3109, 1e-4);
  RgbdFrame frame;
  ASSERT_TRUE(source.Next(&frame));
  EXPECT_TRUE(source.frame_error().empty()) << source.frame_error();
  EXPECT_EQ(frame.depth.size(), 640u * 480u);
  EXPECT_EQ(frame.rgb.size(), 640u * 480u * 3u);
  EXPECT_DOUBLE_EQ(frame.timestamp, 1 / 30.0);
  // The truth's object centre is where the depth image sees a surface: the gelatin box's origin
  // projects onto pixels whose depth is within the box's size of it.
  const Trajectory box = source.Truth(8);
  ASSERT_EQ(box.size(), 10u);
  const Eigen::Vector3d c = box.poses[0].translation;
  const Eigen::Vector2d uv = frame.depth_intrinsics.Project(c);
  const double z = frame.DepthMetres(static_cast<int>(uv.x()), static_cast<int>(uv.y()));
  EXPECT_NEAR(z, c.z(), 0.05);
}

// Writes the YCB-Video frames as a BOP scene, from the MAT arrays directly.
fs::path WriteBopScene(const fs::path& root) {
  const fs::path scene = root / "000048";
  fs::create_directories(scene / "depth");
  fs::create_directories(scene / "rgb");
  nlohmann::json camera, gt, info;
  for (int id = 1; id <= 10; ++id) {
    char stem[16];
    std::snprintf(stem, sizeof(stem), "%06d", id);
    fs::copy_file(kYcb / (std::string(stem) + "-depth.png"), scene / "depth" / (std::string(stem) + ".png"));
    const fs::path meta_file = kYcb / (std::string(stem) + "-meta.mat");
    const MatFile meta = ReadMatFile(meta_file);
    const MatArray& k = meta.arrays.at("intrinsic_matrix");
    nlohmann::json cam_k = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) cam_k.push_back(k.at(r, c));
    }
    const std::string key = std::to_string(id);
    camera[key] = {{"cam_K", cam_k}, {"depth_scale", 1000.0 / meta.arrays.at("factor_depth").values[0]}};
    const MatArray& poses = meta.arrays.at("poses");
    const MatArray& classes = meta.arrays.at("cls_indexes");
    gt[key] = nlohmann::json::array();
    info[key] = nlohmann::json::array();
    for (int j = 0; j < classes.size(); ++j) {
      nlohmann::json r = nlohmann::json::array(), t = nlohmann::json::array();
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) r.push_back(poses.at(a, b, j));
        t.push_back(poses.at(a, 3, j) * 1000);
      }
      gt[key].push_back({{"cam_R_m2c", r}, {"cam_t_m2c", t}, {"obj_id", static_cast<int>(classes.values[j])}});
      info[key].push_back({{"visib_fract", 0.9}});
    }
  }
  WriteText(scene / "scene_camera.json", camera.dump());
  WriteText(scene / "scene_gt.json", gt.dump());
  WriteText(scene / "scene_gt_info.json", info.dump());
  return scene;
}

TEST(RecordingTest, BopSceneOfTheSameFramesReadsTheSame) {
  TempDir dir;
  const fs::path scene = WriteBopScene(dir.path());
  ASSERT_EQ(DetectRecordingLayout(scene), RecordingLayout::kBop);
  RecordingFrameSource bop(scene);
  RecordingFrameSource ycb(kYcb);
  ASSERT_EQ(bop.size(), ycb.size());
  for (int k = 0; k < bop.size(); ++k) {
    const auto& a = bop.frames()[k];
    const auto& b = ycb.frames()[k];
    EXPECT_EQ(a.image_id, b.image_id);
    EXPECT_TRUE(a.intrinsics == b.intrinsics);
    EXPECT_NEAR(a.depth_scale, b.depth_scale, 1e-15);
    ASSERT_EQ(a.truth.size(), b.truth.size());
    for (size_t j = 0; j < a.truth.size(); ++j) {
      EXPECT_EQ(a.truth[j].object_id, b.truth[j].object_id);
      EXPECT_EQ(a.truth[j].visible_fraction, 0.9);
      EXPECT_LT(RotationAngle(a.truth[j].camera_T_object.rotation, b.truth[j].camera_T_object.rotation), 1e-9);
      EXPECT_LT((a.truth[j].camera_T_object.translation - b.truth[j].camera_T_object.translation).norm(), 1e-9);
    }
  }
  RgbdFrame fa, fb;
  ASSERT_TRUE(bop.Next(&fa));
  ASSERT_TRUE(ycb.Next(&fb));
  EXPECT_EQ(fa.depth, fb.depth);
  EXPECT_TRUE(fa.rgb.empty());  // the BOP copy has no colour images
}

TEST(RecordingTest, BadGroundTruthIsAnInputErrorNamingFileAndValue) {
  TempDir dir;
  const fs::path scene = WriteBopScene(dir.path());
  const auto camera = nlohmann::json::parse(test_util::ReadBytes(scene / "scene_camera.json"));
  const auto gt = nlohmann::json::parse(test_util::ReadBytes(scene / "scene_gt.json"));
  // No depth scale.
  auto no_scale = camera;
  no_scale["3"].erase("depth_scale");
  WriteText(scene / "scene_camera.json", no_scale.dump());
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(scene); }),
              HasSubstr("scene_camera.json: image 3: 'depth_scale' is missing"));
  WriteText(scene / "scene_camera.json", camera.dump());
  // An image without ground truth.
  auto missing = gt;
  missing.erase("4");
  WriteText(scene / "scene_gt.json", missing.dump());
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(scene); }),
              HasSubstr("scene_gt.json: image 4 is missing"));
  // A matrix that is not a rotation (a scale of 1000 slipped into it).
  auto scaled = gt;
  for (auto& v : scaled["2"][0]["cam_R_m2c"]) v = v.get<double>() * 1000;
  WriteText(scene / "scene_gt.json", scaled.dump());
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(scene); }),
              HasSubstr("scene_gt.json: image 2, pose 0: rotation"));
  WriteText(scene / "scene_gt.json", gt.dump());
  // scene_gt_info.json of another length.
  auto info = nlohmann::json::parse(test_util::ReadBytes(scene / "scene_gt_info.json"));
  info["5"].erase(0);
  WriteText(scene / "scene_gt_info.json", info.dump());
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(scene); }),
              HasSubstr("scene_gt_info.json: image 5: got 2 entries, expected 3"));
  // YCB-Video: a frame without its meta file, and a meta without factor_depth.
  TempDir ycb;
  fs::copy_file(kYcb / "000001-depth.png", ycb / "000001-depth.png");
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(ycb.path()); }),
              HasSubstr("000001-depth.png: no ground truth beside it"));
  WriteText(ycb / "000001-meta.txt",
            "intrinsic_matrix: 3 3\n1066 0 0 0 1067 0 313 241 1\ncls_indexes: 1 1\n8\n"
            "poses: 3 4 1\n1 0 0 0 1 0 0 0 1 0 0 0.6\n");
  EXPECT_THAT(ErrorOf([&] { RecordingFrameSource s(ycb.path()); }),
              HasSubstr("000001-meta.txt: variable 'factor_depth' is missing"));
}

}  // namespace
}  // namespace mmh::track
