// Real recordings read as depth sequences for `mmh sensor-check`: a TUM RGB-D folder and a
// YCB-Video folder, against their depth images decoded directly.
#include "pipeline/depth_sequence.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/image_io.h"

namespace mmh::pipeline {
namespace {

const std::filesystem::path kTum =
    std::filesystem::path(MMH_SOURCE_DIR) / "tests/data/real/tum/rgbd_dataset_freiburg1_xyz";
const std::filesystem::path kYcb =
    std::filesystem::path(MMH_SOURCE_DIR) / "tests/data/real/ycbv/data/0000";

TEST(DepthSequence, ReadsATumFolderWithItsFreiburgCalibration) {
  const sim::DepthSequence sequence = ReadDepthSequence(kTum, 2);
  EXPECT_EQ(sequence.name, "real TUM rgbd_dataset_freiburg1_xyz");
  ASSERT_EQ(sequence.depth_m.size(), 2u);
  EXPECT_EQ(sequence.width, 640);
  EXPECT_EQ(sequence.height, 480);
  EXPECT_DOUBLE_EQ(sequence.intrinsics.fx, 517.3);
  EXPECT_DOUBLE_EQ(sequence.intrinsics.cy, 255.3);
  // The second frame is depth/1305031102.262886.png, 5000 units per metre.
  const DepthImage png = ReadDepthPng16(kTum / "depth/1305031102.262886.png");
  ASSERT_EQ(png.values.size(), sequence.depth_m[1].size());
  int valid = 0;
  for (size_t i = 0; i < png.values.size(); ++i) {
    EXPECT_FLOAT_EQ(sequence.depth_m[1][i], static_cast<float>(png.values[i] / 5000.0));
    valid += png.values[i] > 0;
  }
  EXPECT_GT(valid, 200000);
}

TEST(DepthSequence, NegativeCountsReadAsManyAsThereAreUpToTheirSize) {
  EXPECT_EQ(ReadDepthSequence(kTum, -10).depth_m.size(), 2u);
  EXPECT_EQ(ReadDepthSequence(kTum, -1).depth_m.size(), 1u);
  const sim::DepthSequence ycb = ReadDepthSequence(kYcb, -3);
  EXPECT_EQ(ycb.depth_m.size(), 3u);
  EXPECT_EQ(ycb.name, "real YCB-Video folder 0000");
  EXPECT_NEAR(ycb.intrinsics.fx, 1066.778, 1e-3);
}

TEST(DepthSequence, TooFewFramesNameTheFolder) {
  try {
    ReadDepthSequence(kTum, 3);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rgbd_dataset_freiburg1_xyz: frames"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("at least 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mmh::pipeline
