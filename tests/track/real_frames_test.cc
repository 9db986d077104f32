// The table/floor plane and the segmentation on real Kinect v1 frames (../shared/data/real-rgbd:
// TUM, NYU Depth V2 raw, SUN RGB-D): they run without error and give plausible results (the
// figures are in docs/tracker.md). No setup calibration: the table frame comes from the plane.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/image_io.h"
#include "track/freenect_source.h"
#include "track/segmentation.h"
#include "track/table_plane.h"

namespace mmh::track {
namespace {

namespace fs = std::filesystem;

fs::path RealFrames() { return fs::path(MMH_SOURCE_DIR) / ".." / "shared" / "data" / "real-rgbd"; }

RgbdFrame FrameOf(const std::vector<uint16_t>& depth_units, const RgbImage& colour) {
  RgbdFrame frame;
  frame.depth = depth_units;
  frame.rgb = colour.rgb;
  frame.depth_intrinsics.width = frame.color_intrinsics.width = colour.width;
  frame.depth_intrinsics.height = frame.color_intrinsics.height = colour.height;
  return frame;
}

void CheckPlausible(const std::string& name, const RgbdFrame& frame) {
  std::string why;
  const auto plane = EstimateTablePlane(frame, TablePlaneOptions(), std::nullopt, &why);
  ASSERT_TRUE(plane) << name << ": " << why;
  const double tilt = std::acos(-plane->normal.y()) * 180 / M_PI;  // from the image's up
  std::printf(
      "%s: plane normal (%.3f, %.3f, %.3f), %.0f deg from image up, camera %.3f m above "
      "it, %.1f %% of the sampled pixels within 12 mm (RMS %.1f mm), %d planes found\n",
      name.c_str(), plane->normal.x(), plane->normal.y(), plane->normal.z(), tilt, plane->offset,
      100 * plane->inlier_share, 1000 * plane->rms_distance, plane->candidates);
  // A horizontal surface below a hand-held or tripod camera: above it by 0.3..2.5 m, its normal
  // within 70 deg of the image's up, a good part of the image, a tight fit.
  EXPECT_GT(plane->offset, 0.3) << name;
  EXPECT_LT(plane->offset, 2.5) << name;
  EXPECT_LT(tilt, 70.0) << name;
  EXPECT_GT(plane->inlier_share, 0.1) << name;
  EXPECT_LT(plane->rms_distance, 0.008) << name;

  TrackSetup setup;  // a 40 x 30 cm play area where the optical axis meets the plane
  setup.like_box_length = 0;
  Segmenter segmenter(SegmentationOptions(), setup);
  segmenter.SetTable(TableFrameOnPlane(*plane, std::nullopt), frame.depth_intrinsics);
  Segmentation segmentation;
  segmenter.Segment(frame, &segmentation);
  std::printf(
      "%s: play volume's image [%d, %d) x [%d, %d), %d foreground pixels (%d skin), %zu "
      "components kept (largest %d px), %d px in small components dropped\n",
      name.c_str(), segmentation.roi.x0, segmentation.roi.x1, segmentation.roi.y0,
      segmentation.roi.y1, segmentation.foreground_pixels, segmentation.skin_pixels,
      segmentation.component_sizes.size(),
      segmentation.component_sizes.empty() ? 0 : segmentation.component_sizes[0],
      segmentation.dropped_pixels);
  EXPECT_FALSE(segmentation.roi.empty()) << name;
  // Every kept point lies above the plane.
  for (const auto& p : segmentation.points) {
    ASSERT_GT(plane->Height(p.cast<double>()), 0.0) << name;
  }
}

TEST(RealFramesTest, TumFrame) {
  if (!fs::exists(RealFrames() / "TUM_depth.png")) GTEST_SKIP() << "no real frames";
  const DepthImage depth = ReadDepthPng16(RealFrames() / "TUM_depth.png");
  CheckPlausible("TUM", FrameOf(depth.values, ReadRgbImage(RealFrames() / "TUM_color.png")));
}

TEST(RealFramesTest, NyuRawFrame) {
  if (!fs::exists(RealFrames() / "NYU_depth.pgm")) GTEST_SKIP() << "no real frames";
  const DepthImage raw = ReadNyuRawDisparity(RealFrames() / "NYU_depth.pgm");
  // The NYU calibration z = 351.3 / (1092.5 - raw): s f b = 351.3 px m.
  FreenectOptions law;
  law.ir_focal_length = 351.3 / (law.subpixel_steps * law.baseline);
  std::vector<uint16_t> units(raw.values.size());
  for (size_t i = 0; i < units.size(); ++i) {
    units[i] = DepthUnitsFromRaw(raw.values[i], law, kTumDepthScale);
  }
  CheckPlausible("NYU", FrameOf(units, ReadRgbImage(RealFrames() / "NYU_color.ppm")));
}

TEST(RealFramesTest, SunFrame) {
  if (!fs::exists(RealFrames() / "SUN_depth.png")) GTEST_SKIP() << "no real frames";
  const DepthImage mm = ReadSunDepth(RealFrames() / "SUN_depth.png");
  std::vector<uint16_t> units(mm.values.size());
  for (size_t i = 0; i < units.size(); ++i) {
    units[i] =
        static_cast<uint16_t>(std::min(65535.0, std::round(mm.values[i] * 0.001 / kTumDepthScale)));
  }
  const RgbImage colour = ReadRgbImage(RealFrames() / "SUN_color.jpg");
  ASSERT_EQ(colour.width, mm.width);
  CheckPlausible("SUN", FrameOf(units, colour));
}

}  // namespace
}  // namespace mmh::track
