// The segmentation's connected components with and without the depth limit
// (SegmentationOptions::max_depth_jump): two blocks that touch in the image at different heights
// above the table are one component by the image's connectivity and two with the limit, each
// without its outline (the pixels at a depth step join nothing and are dropped as small
// components).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>
#include <string>

#include "core/error.h"
#include "track/segmentation.h"

namespace mmh::track {
namespace {

// An 80 x 80 px camera looking straight down at a table 1 m below it; block A (columns 20-39) is
// 10 cm high, block B (columns 40-59) 20 cm high, both over rows 20-59.
RgbdFrame TwoBlocks() {
  RgbdFrame frame;
  PinholeIntrinsics& k = frame.depth_intrinsics;
  k.width = k.height = 80;
  k.fx = k.fy = 100;
  k.cx = k.cy = 40;
  frame.color_intrinsics = k;
  frame.depth_scale = 0.001;
  frame.depth.assign(80 * 80, 1000);
  for (int v = 20; v < 60; ++v) {
    for (int u = 20; u < 60; ++u) frame.depth[v * 80 + u] = u < 40 ? 900 : 800;
  }
  return frame;
}

Segmentation SegmentTwoBlocks(double max_depth_jump, int window_span = 0, int outline_span = 0) {
  TrackSetup setup;
  setup.play_area_width = setup.play_area_depth = 1.0;
  setup.like_box_length = 0;
  SegmentationOptions options;
  options.skin = false;
  options.background = false;
  options.max_depth_jump = max_depth_jump;
  options.window_span = window_span;
  options.outline_span = outline_span;
  Segmenter segmenter(options, setup);
  // The table's z axis points at the camera: a half turn about x, its origin 1 m ahead.
  const Rigid3 camera_T_table(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0, 0, 1));
  const RgbdFrame frame = TwoBlocks();
  segmenter.SetTable(camera_T_table, frame.depth_intrinsics);
  Segmentation segmentation;
  segmenter.Segment(frame, &segmentation);
  return segmentation;
}

TEST(SegmentationTest, ImageConnectivityJoinsBlocksAtDifferentDepths) {
  const Segmentation s = SegmentTwoBlocks(0.0);
  ASSERT_EQ(s.component_sizes.size(), 1u);
  EXPECT_EQ(s.component_sizes[0], 40 * 40);
  EXPECT_EQ(s.dropped_pixels, 0);
}

TEST(SegmentationTest, DepthLimitSeparatesBlocksAndDropsTheirOutlines) {
  const Segmentation s = SegmentTwoBlocks(0.01);
  // Each block keeps its 18 x 38 inner pixels: its outline borders the table (10 or 20 cm lower)
  // or the other block (10 cm apart).
  ASSERT_EQ(s.component_sizes.size(), 2u);
  EXPECT_EQ(s.component_sizes[0], 18 * 38);
  EXPECT_EQ(s.component_sizes[1], 18 * 38);
  EXPECT_EQ(s.dropped_pixels, 40 * 40 - 2 * 18 * 38);
  // The blocks' points keep their depths: component 0 (the first found, A) at 0.9 m.
  for (size_t i = 0; i < s.points.size(); ++i) {
    EXPECT_FLOAT_EQ(s.points[i].z(), s.components[i] == 0 ? 0.9f : 0.8f);
  }
}

// SegmentationOptions::window_span: a point is kept only where the depths window_span px to
// either side along its row and column exist and lie on a line with it. The blocks' faces are
// flat and every step is 10 cm, so with span 2 exactly the pixels at least 2 px inside their own
// block's outline stay: 16 x 36 of each block.
TEST(SegmentationTest, WindowSpanKeepsPointsWhoseWindowIsFlat) {
  const Segmentation plain = SegmentTwoBlocks(0.0);
  EXPECT_EQ(plain.points.size(), 40u * 40u);
  EXPECT_EQ(plain.window_dropped_pixels, 0);
  const Segmentation s = SegmentTwoBlocks(0.0, 2);
  EXPECT_EQ(s.points.size(), 2u * 16u * 36u);
  EXPECT_EQ(s.window_dropped_pixels, 40 * 40 - 2 * 16 * 36);
  for (const Eigen::Vector3f& p : s.points) {
    // Column u = 40 + 100 x / z: inside 22..37 or 42..57.
    const double u = 40 + 100 * p.x() / p.z();
    EXPECT_TRUE((u > 21.5 && u < 37.5) || (u > 41.5 && u < 57.5)) << u;
  }
}

// SegmentationOptions::outline_span flags, and keeps, the points within outline_span px of a
// depth step or hole along their row or column: with span 2 every step of the two blocks is 10 cm,
// so all but each block's 16 x 36 pixels at least 2 px inside its outline are flagged.
TEST(SegmentationTest, OutlineSpanFlagsTheBandAndKeepsIt) {
  EXPECT_TRUE(SegmentTwoBlocks(0.0).outline.empty());
  const Segmentation s = SegmentTwoBlocks(0.0, 0, 2);
  ASSERT_EQ(s.points.size(), 40u * 40u);
  ASSERT_EQ(s.outline.size(), s.points.size());
  int flagged = 0;
  for (size_t i = 0; i < s.points.size(); ++i) {
    flagged += s.outline[i];
    const double u = 40 + 100 * s.points[i].x() / s.points[i].z();
    const double v = 40 + 100 * s.points[i].y() / s.points[i].z();
    const bool inside = ((u > 21.5 && u < 37.5) || (u > 41.5 && u < 57.5)) && v > 21.5 && v < 57.5;
    EXPECT_EQ(s.outline[i] != 0, !inside) << u << " " << v;
  }
  EXPECT_EQ(flagged, 40 * 40 - 2 * 16 * 36);
  SegmentationOptions options;
  options.outline_span = 33;
  try {
    options.Validate("segmentation");
    ADD_FAILURE() << "span 33 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("segmentation.outline_span: got 33"), std::string::npos);
  }
}

// SegmentationOptions::skin_grow_px: the hand's depth past its colour outline. Block A (0.9 m)
// shows skin in its columns 20-29 and grey in 30-39 at the same depth (the bleed); block B (0.8
// m, grey) touches A's grey at a 10 cm step. Each pass turns one more column of A's grey into
// skin; B, at another depth, and the rest of A stay proxy candidates.
TEST(SegmentationTest, SkinGrowsOverCandidatesAtItsDepthOnly) {
  RgbdFrame frame = TwoBlocks();
  frame.rgb.assign(3 * 80 * 80, 128);  // grey: Cr = Cb = 128, outside the skin box
  for (int v = 20; v < 60; ++v) {
    for (int u = 20; u < 30; ++u) {
      uint8_t* p = &frame.rgb[3 * (v * 80 + u)];
      p[0] = 224, p[1] = 172, p[2] = 140;  // Cr 157, Cb 103: skin
    }
  }
  TrackSetup setup;
  setup.play_area_width = setup.play_area_depth = 1.0;
  setup.like_box_length = 0;
  const Rigid3 camera_T_table(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(0, 0, 1));
  for (const int grow : {0, 1, 2}) {
    SCOPED_TRACE("skin_grow_px " + std::to_string(grow));
    SegmentationOptions options;
    options.background = false;
    options.skin_grow_px = grow;
    Segmenter segmenter(options, setup);
    segmenter.SetTable(camera_T_table, frame.depth_intrinsics);
    Segmentation s;
    segmenter.Segment(frame, &s);
    EXPECT_EQ(s.skin_points.size(), static_cast<size_t>((10 + grow) * 40));
    EXPECT_EQ(s.points.size(), static_cast<size_t>((30 - grow) * 40));
    for (const Eigen::Vector3f& p : s.points) {
      const double u = 40 + 100 * p.x() / p.z();
      EXPECT_GT(u, 29.5 + grow) << "a grey pixel of A within reach of the skin stayed";
    }
  }
  SegmentationOptions bad;
  bad.skin_grow_px = 9;
  EXPECT_THROW(bad.Validate("segmentation"), InputError);
}

TEST(SegmentationTest, NegativeDepthJumpIsRejected) {
  SegmentationOptions options;
  options.max_depth_jump = -0.01;
  EXPECT_THROW(options.Validate("segmentation"), InputError);
}

TEST(SegmentationTest, BadWindowSpanIsRejectedByName) {
  for (const int span : {-1, 33}) {
    SegmentationOptions options;
    options.window_span = span;
    try {
      options.Validate("segmentation");
      ADD_FAILURE() << span;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("segmentation.window_span"), std::string::npos);
    }
  }
  SegmentationOptions options;
  options.window_tolerance = 0;
  EXPECT_THROW(options.Validate("segmentation"), InputError);
}

}  // namespace
}  // namespace mmh::track
