// The table/floor plane and the segmentation on real Kinect v1 frames (../shared/data/real-rgbd:
// TUM, NYU Depth V2 raw, SUN RGB-D): they run without error and give the floor plane measured on
// each (the figures are in docs/tracker.md). The frames are outside the repository: the tests
// skip where ../shared/data/real-rgbd is absent (a worktree elsewhere). No setup calibration: the table frame comes from the plane.
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

// A frame's plane as measured on 2026-11-28 (docs/tracker.md, "Real frames"; the test prints it):
// the camera's height above it [m], the normal's tilt from the image's up [deg], the share of the
// sampled pixels within 12 mm of it and their RMS distance [m]. The plane's RANSAC is seeded (the
// same frame gives the same plane); the bounds allow 3 cm of height, 2 deg of tilt, 2 points of
// inlier share and 0.5 mm of RMS for other compilers and small intended changes.
struct MeasuredPlane {
  double offset, tilt_deg, inlier_share, rms_distance;
};

void CheckPlausible(const std::string& name, const RgbdFrame& frame, const MeasuredPlane& measured) {
  std::string why;
  const auto plane = EstimateTablePlane(frame, TablePlaneOptions(), std::nullopt, &why);
  ASSERT_TRUE(plane) << name << ": " << why;
  const double tilt = std::acos(-plane->normal.y()) * 180 / M_PI;  // from the image's up
  std::printf(
      "%s: plane normal (%.3f, %.3f, %.3f), %.0f deg from image up, camera %.3f m above "
      "it, %.1f %% of the sampled pixels within 12 mm (RMS %.1f mm), %d planes found\n",
      name.c_str(), plane->normal.x(), plane->normal.y(), plane->normal.z(), tilt, plane->offset,
      100 * plane->inlier_share, 1000 * plane->rms_distance, plane->candidates);
  // The floor below a hand-held camera, as measured.
  EXPECT_NEAR(plane->offset, measured.offset, 0.03) << name;
  EXPECT_NEAR(tilt, measured.tilt_deg, 2.0) << name;
  EXPECT_GT(plane->inlier_share, measured.inlier_share - 0.02) << name;
  EXPECT_LT(plane->rms_distance, measured.rms_distance + 0.0005) << name;

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
  CheckPlausible("TUM", FrameOf(depth.values, ReadRgbImage(RealFrames() / "TUM_color.png")),
                 {1.107, 30.2, 0.107, 0.0060});
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
  CheckPlausible("NYU", FrameOf(units, ReadRgbImage(RealFrames() / "NYU_color.ppm")),
                 {1.620, 16.1, 0.190, 0.0064});
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
  CheckPlausible("SUN", FrameOf(units, colour), {1.139, 3.6, 0.134, 0.0063});
}

}  // namespace
}  // namespace mmh::track
