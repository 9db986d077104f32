// Tests of core/rgbd_folder.h: bit-identical round trip, staging and replacement rules, public
// TUM sequences without camera.json, association, and error messages.
#include "core/rgbd_folder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/image_io.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test_util::ErrorOf;
using test_util::ReadBytes;
using test_util::TempDir;
using test_util::WriteText;

RgbdCameraInfo SmallCamera() {
  RgbdCameraInfo camera;
  camera.depth_intrinsics = {16, 12, 20.5, 21.25, 7.5, 5.5};
  camera.color_intrinsics = {16, 12, 19.0, 19.5, 7.25, 5.75};
  camera.color_T_depth =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(-0.025, 0.001, 0.0));
  camera.sensor = {{"model", "kinect-v1"}, {"ir_focal_length", 580.0}};
  return camera;
}

RgbdFrame MakeFrame(const RgbdCameraInfo& camera, int index, double timestamp) {
  std::mt19937 rng(index + 17);
  RgbdFrame frame;
  frame.index = index;
  frame.timestamp = timestamp;
  frame.depth_scale = camera.depth_scale;
  frame.depth_intrinsics = camera.depth_intrinsics;
  frame.color_intrinsics = camera.color_intrinsics;
  frame.color_T_depth = camera.color_T_depth;
  frame.depth.resize(camera.depth_intrinsics.pixel_count());
  for (auto& d : frame.depth) d = (rng() % 4 == 0) ? 0 : static_cast<uint16_t>(rng());
  frame.rgb.resize(camera.color_intrinsics.pixel_count() * 3);
  for (auto& c : frame.rgb) c = static_cast<uint8_t>(rng());
  return frame;
}

// Whole microseconds read back exactly (rgbd_folder.h).
double MicrosecondTime(int i) { return std::round(1e6 * (100.0 + i / 30.0)) / 1e6; }

TEST(RgbdFolderTest, RoundTripIsBitIdentical) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  std::vector<RgbdFrame> frames;
  Trajectory truth;
  {
    RgbdFolderWriter writer(dir / "seq", camera);
    for (int i = 0; i < 5; ++i) {
      frames.push_back(MakeFrame(camera, i, MicrosecondTime(i)));
      writer.Add(frames.back());
      truth.timestamps.push_back(frames.back().timestamp);
      truth.poses.emplace_back(
          Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ())),
          Eigen::Vector3d(0.1 * i, 0.2, 1.0 / 3.0));
    }
    // Nothing appears at the target before Finish().
    EXPECT_FALSE(fs::exists(dir / "seq"));
    EXPECT_TRUE(fs::exists(writer.staging()));
    writer.Finish(truth, {{"take", 3}});
    EXPECT_FALSE(fs::exists(writer.staging()));
  }
  ASSERT_TRUE(fs::is_directory(dir / "seq"));
  EXPECT_TRUE(fs::exists(dir / "seq" / "depth" / "100.000000.png"));
  EXPECT_TRUE(fs::exists(dir / "seq" / "rgb" / "100.033333.png"));
  EXPECT_THAT(ReadBytes(dir / "seq" / "depth.txt"),
              HasSubstr("# timestamp filename\n100.000000 depth/100.000000.png\n"
                        "100.033333 depth/100.033333.png\n"));

  RgbdFolderReader reader(dir / "seq");
  ASSERT_EQ(reader.size(), 5);
  EXPECT_EQ(reader.camera().depth_intrinsics, camera.depth_intrinsics);
  EXPECT_EQ(reader.camera().color_intrinsics, camera.color_intrinsics);
  EXPECT_EQ(reader.camera().depth_scale, camera.depth_scale);
  EXPECT_EQ(reader.camera().color_T_depth.translation, camera.color_T_depth.translation);
  EXPECT_EQ(reader.camera().color_T_depth.rotation.coeffs(),
            camera.color_T_depth.rotation.coeffs());
  EXPECT_EQ(reader.camera().sensor, camera.sensor);
  EXPECT_EQ(reader.extra(), nlohmann::json({{"take", 3}}));
  for (int i = 0; i < 5; ++i) {
    const RgbdFrame back = reader.Read(i);
    EXPECT_EQ(back.index, i);
    EXPECT_EQ(back.timestamp, frames[i].timestamp) << i;
    EXPECT_EQ(back.depth, frames[i].depth) << i;
    EXPECT_EQ(back.rgb, frames[i].rgb) << i;
    EXPECT_EQ(back.depth_intrinsics, camera.depth_intrinsics);
  }
  const auto groundtruth = reader.ReadGroundtruth();
  ASSERT_TRUE(groundtruth.has_value());
  ASSERT_EQ(groundtruth->size(), 5u);
  EXPECT_EQ(groundtruth->poses[4].translation, truth.poses[4].translation);
}

TEST(RgbdFolderTest, ParallelAddsAreSortedByTimestamp) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  {
    RgbdFolderWriter writer(dir / "par", camera);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
      threads.emplace_back([&, t] {
        for (int i = t; i < 12; i += 4) writer.Add(MakeFrame(camera, i, MicrosecondTime(11 - i)));
      });
    }
    for (auto& thread : threads) thread.join();
    writer.Finish();
  }
  RgbdFolderReader reader(dir / "par");
  ASSERT_EQ(reader.size(), 12);
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(reader.depth_timestamp(i), MicrosecondTime(i));
    EXPECT_EQ(reader.Read(i).depth, MakeFrame(camera, 11 - i, 0).depth);
  }
  EXPECT_FALSE(reader.ReadGroundtruth().has_value());
}

TEST(RgbdFolderTest, DestructorWithoutFinishLeavesNothing) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  fs::path staging;
  {
    RgbdFolderWriter writer(dir / "never", camera);
    staging = writer.staging();
    writer.Add(MakeFrame(camera, 0, 1.0));
    EXPECT_TRUE(fs::exists(staging));
  }
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(dir / "never"));
}

TEST(RgbdFolderTest, ReplacesOnlyEmptyOrOwnFolders) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  // An empty folder is replaced.
  fs::create_directories(dir / "empty");
  {
    RgbdFolderWriter writer(dir / "empty", camera);
    writer.Add(MakeFrame(camera, 0, 1.0));
    writer.Finish();
  }
  EXPECT_EQ(RgbdFolderReader(dir / "empty").size(), 1);
  // Our own folder is replaced, old content gone.
  {
    RgbdFolderWriter writer(dir / "empty", camera);
    writer.Add(MakeFrame(camera, 0, 2.0));
    writer.Add(MakeFrame(camera, 1, 3.0));
    writer.Finish();
  }
  EXPECT_EQ(RgbdFolderReader(dir / "empty").size(), 2);
  EXPECT_FALSE(fs::exists(dir / "empty" / "rgb" / "1.000000.png"));
  // Anything else is refused, naming the folder.
  fs::create_directories(dir / "precious");
  WriteText(dir / "precious" / "thesis.tex", "do not delete");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderWriter writer(dir / "precious", camera); }),
              HasSubstr((dir / "precious").string() + ": got an existing folder that mmh did not "
                                                      "write"));
  WriteText(dir / "file", "x");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderWriter writer(dir / "file", camera); }),
              HasSubstr("got an existing file"));
  EXPECT_TRUE(fs::exists(dir / "precious" / "thesis.tex"));
  // A folder that appears while writing is checked again in Finish().
  {
    RgbdFolderWriter writer(dir / "late", camera);
    writer.Add(MakeFrame(camera, 0, 1.0));
    fs::create_directories(dir / "late");
    WriteText(dir / "late" / "mine.txt", "x");
    EXPECT_THAT(ErrorOf([&] { writer.Finish(); }), HasSubstr("did not write"));
  }
  EXPECT_TRUE(fs::exists(dir / "late" / "mine.txt"));
}

TEST(RgbdFolderTest, AddChecksTheFrame) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  RgbdFolderWriter writer(dir / "checks", camera);
  RgbdFrame frame = MakeFrame(camera, 7, 1.0);
  frame.depth.pop_back();
  EXPECT_THAT(ErrorOf([&] { writer.Add(frame); }),
              HasSubstr("frame 7, depth: got 191 pixels, expected 192 = 16x12"));
  frame = MakeFrame(camera, 8, 1.0);
  frame.rgb.resize(10);
  EXPECT_THAT(ErrorOf([&] { writer.Add(frame); }), HasSubstr("frame 8, rgb: got 10 bytes"));
  frame = MakeFrame(camera, 9, 1.0);
  frame.depth_intrinsics.fx = 500;
  EXPECT_THAT(ErrorOf([&] { writer.Add(frame); }), HasSubstr("frame 9: got intrinsics"));
  frame = MakeFrame(camera, 10, 1.0);
  frame.depth_scale = 0.001;
  EXPECT_THAT(ErrorOf([&] { writer.Add(frame); }), HasSubstr("frame 10, depth_scale: got 0.001"));
  frame = MakeFrame(camera, 11, std::nan(""));
  EXPECT_THAT(ErrorOf([&] { writer.Add(frame); }), HasSubstr("frame 11, timestamp: got nan"));
  writer.Add(MakeFrame(camera, 12, 1.0));
  EXPECT_THAT(ErrorOf([&] { writer.Add(MakeFrame(camera, 13, 1.0000001)); }),
              HasSubstr("frame 13, timestamp"));
  EXPECT_THAT(ErrorOf([&] {
                RgbdFolderWriter empty(dir / "none", camera);
                empty.Finish();
              }),
              HasSubstr("no frames"));
}

// A public TUM RGB-D sequence: no camera.json, rgb and depth at different times.
void WritePublicTum(const fs::path& folder) {
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  DepthImage depth{640, 480, std::vector<uint16_t>(640 * 480, 5000)};
  RgbImage rgb{640, 480, std::vector<uint8_t>(640 * 480 * 3, 7)};
  const double rgb_times[] = {1305031102.175304, 1305031102.211214, 1305031102.243211,
                              1305031102.275326};
  const double depth_times[] = {1305031102.160407, 1305031102.194330, 1305031102.226738,
                                1305031102.262886, 1305031102.295279};
  std::ostringstream rgb_list, depth_list;
  rgb_list << "# color images\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n";
  depth_list << "# depth maps\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n";
  char name[64];
  for (double t : rgb_times) {
    std::snprintf(name, sizeof(name), "%.6f.png", t);
    WriteRgbPng(folder / "rgb" / name, rgb);
    rgb_list << std::string(name, std::strlen(name) - 4) << " rgb/" << name << "\n";
  }
  int k = 0;
  for (double t : depth_times) {
    std::snprintf(name, sizeof(name), "%.6f.png", t);
    depth.values[0] = static_cast<uint16_t>(k++);
    WriteDepthPng16(folder / "depth" / name, depth);
    depth_list << std::string(name, std::strlen(name) - 4) << " depth/" << name << "\n";
  }
  WriteText(folder / "rgb.txt", rgb_list.str());
  WriteText(folder / "depth.txt", depth_list.str());
}

TEST(RgbdFolderTest, ReadsPublicTumSequences) {
  TempDir dir;
  const fs::path folder = dir / "rgbd_dataset_freiburg1_xyz";
  WritePublicTum(folder);
  RgbdFolderReader reader(folder.string() + "/");
  // associate.py, greedy by difference: (rgb .275326, depth .262886) 0.0124, (.175304, .160407)
  // 0.0149, (.211214, .226738) 0.0155; rgb .243211 then finds both its depth candidates taken.
  ASSERT_EQ(reader.size(), 3);
  EXPECT_EQ(reader.camera().depth_intrinsics.fx, 517.3);
  EXPECT_EQ(reader.camera().depth_intrinsics.cy, 255.3);
  EXPECT_EQ(reader.camera().depth_scale, 1.0 / 5000);
  const RgbdFrame frame = reader.Read(0);
  EXPECT_EQ(frame.timestamp, 1305031102.160407);
  EXPECT_EQ(reader.rgb_timestamp(0), 1305031102.175304);
  EXPECT_EQ(frame.depth[0], 0);
  EXPECT_EQ(frame.DepthMetres(5, 5), 1.0);
  EXPECT_EQ(reader.Read(1).depth[0], 2);
  EXPECT_EQ(reader.Read(2).depth[0], 3);
  EXPECT_EQ(reader.rgb_timestamp(2), 1305031102.275326);

  // The same folder under another name needs explicit intrinsics.
  fs::rename(folder, dir / "mine");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(dir / "mine"); }),
              HasSubstr("no camera.json and a folder name without 'freiburg1'"));
  PinholeIntrinsics intrinsics;
  intrinsics.fx = 600;
  RgbdFolderReader explicit_reader(dir / "mine", intrinsics);
  EXPECT_EQ(explicit_reader.camera().depth_intrinsics.fx, 600);
  EXPECT_EQ(explicit_reader.size(), 3);
}

TEST(RgbdFolderTest, TumNames) {
  EXPECT_EQ(TumCameraInfoFromName("rgbd_dataset_freiburg2_desk")->depth_intrinsics.fx, 520.9);
  EXPECT_EQ(
      TumCameraInfoFromName("rgbd_dataset_freiburg3_long_office_household")->depth_intrinsics.fy,
      539.2);
  EXPECT_FALSE(TumCameraInfoFromName("my_take").has_value());
}

TEST(RgbdFolderTest, AssociationIsGreedyByDifference) {
  // rgb 0.000 could take depth 0.015 or 0.019; rgb 0.030 is closest to 0.019 (0.011), so the
  // greedy pass gives rgb 0.030 -> 0.019 and rgb 0.000 -> 0.015.
  const auto matches = AssociateTimestamps({0.030, 0.000, 1.0}, {0.019, 0.015, 0.5}, 0.02);
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0], std::make_pair(1, 1));
  EXPECT_EQ(matches[1], std::make_pair(0, 0));
  EXPECT_TRUE(AssociateTimestamps({0.0}, {0.02}, 0.02).empty());  // strictly closer
}

TEST(RgbdFolderTest, ReaderErrorsNameTheFileAndLine) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  {
    RgbdFolderWriter writer(dir / "s", camera);
    writer.Add(MakeFrame(camera, 0, 1.0));
    writer.Add(MakeFrame(camera, 1, 2.0));
    writer.Finish();
  }
  const fs::path s = dir / "s";
  const std::string good_depth = ReadBytes(s / "depth.txt");
  WriteText(s / "depth.txt", good_depth + "3.0 depth/3.000000.png extra\n");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }),
              HasSubstr((s / "depth.txt").string() + ":6: got 3 fields"));
  WriteText(s / "depth.txt", good_depth + "three depth/x.png\n");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }),
              HasSubstr("depth.txt:6, timestamp: got 'three'"));
  WriteText(s / "depth.txt", good_depth + "3.0 depth/3.000000.png\n");
  WriteText(s / "rgb.txt", ReadBytes(s / "rgb.txt") + "3.0 rgb/3.000000.png\n");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }),
              HasSubstr("rgb.txt:6: got 'rgb/3.000000.png', which does not exist"));
  WriteText(s / "depth.txt", good_depth);
  WriteText(s / "rgb.txt", "# nothing\n");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }), HasSubstr("rgb.txt: got no entries"));
  fs::remove(s / "rgb.txt");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }), HasSubstr("rgb.txt: got a path that"));
}

TEST(RgbdFolderTest, ReaderChecksImageSizesAndCameraJson) {
  TempDir dir;
  const RgbdCameraInfo camera = SmallCamera();
  {
    RgbdFolderWriter writer(dir / "s", camera);
    writer.Add(MakeFrame(camera, 0, 1.0));
    writer.Finish();
  }
  const fs::path s = dir / "s";
  WriteDepthPng16(s / "depth" / "1.000000.png", DepthImage{8, 8, std::vector<uint16_t>(64)});
  RgbdFolderReader reader(s);
  EXPECT_THAT(ErrorOf([&] { reader.Read(0); }),
              HasSubstr("1.000000.png: got an image of 8x8 px, expected 16x12 px"));

  nlohmann::json json = nlohmann::json::parse(ReadBytes(s / "camera.json"));
  json["depth_scal"] = 0.001;
  WriteText(s / "camera.json", json.dump());
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }), HasSubstr("the unknown key 'depth_scal'"));
  json.erase("depth_scal");
  json["depth_intrinsics"].erase("fx");
  WriteText(s / "camera.json", json.dump());
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }), HasSubstr("depth_intrinsics: got no 'fx'"));
  WriteText(s / "camera.json", "{ not json");
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(s); }), HasSubstr("invalid JSON"));
  EXPECT_THAT(ErrorOf([&] { RgbdFolderReader r(dir / "absent"); }),
              HasSubstr("absent: got a path that does not exist"));
}

}  // namespace
}  // namespace mmh
