// The silhouette's bleed and erosion on depth images drawn with known ones, row by row.
#include "sim/silhouette_bleed.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"

namespace mmh::sim {
namespace {

constexpr int kWidth = 120, kHeight = 40;
constexpr int kLeft = 40, kRight = 79;  // the object's columns, rows kTop .. kBottom
constexpr int kTop = 10, kBottom = 29;

// A 40 x 20 px object at 1 m before a background at `background_m`. In row v the object bleeds
// v % 4 pixels onto the background on its left, then 2 pixels are missing (a shadow), and its own
// v % 3 rightmost pixels are missing (eroded).
struct Drawn {
  std::vector<float> depth_m = std::vector<float>(kWidth * kHeight);
  std::vector<uint8_t> mask = std::vector<uint8_t>(kWidth * kHeight, 0);
  double left_bleed = 0, right_erosion = 0, bled_share = 0;
};

Drawn Draw(float background_m) {
  Drawn d;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) d.depth_m[v * kWidth + u] = background_m;
  }
  const int rows = kBottom - kTop + 1;
  for (int v = kTop; v <= kBottom; ++v) {
    for (int u = kLeft; u <= kRight; ++u) {
      d.mask[v * kWidth + u] = 1;
      d.depth_m[v * kWidth + u] = 1.0f + 0.002f * (u - kLeft);  // a slanted face
    }
    const int bleed = v % 4, erosion = v % 3;
    for (int k = 1; k <= bleed; ++k) d.depth_m[v * kWidth + kLeft - k] = 1.004f;
    d.depth_m[v * kWidth + kLeft - bleed - 1] = 0;
    d.depth_m[v * kWidth + kLeft - bleed - 2] = 0;
    for (int k = 0; k < erosion; ++k) d.depth_m[v * kWidth + kRight - k] = 0;
    d.left_bleed += static_cast<double>(bleed) / rows;
    d.right_erosion += static_cast<double>(erosion) / rows;
    d.bled_share += (bleed > 0 ? 1.0 : 0.0) / rows;
  }
  return d;
}

TEST(SilhouetteBleed, CountsTheDrawnBleedAndErosionOnEachSide) {
  const Drawn d = Draw(1.5f);
  const SilhouetteBleed b = MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask);
  EXPECT_EQ(b.shadow_side.ends, kBottom - kTop + 1);
  EXPECT_EQ(b.edge_side.ends, kBottom - kTop + 1);
  EXPECT_DOUBLE_EQ(b.shadow_side.bleed_px, d.left_bleed);
  EXPECT_DOUBLE_EQ(b.shadow_side.bled_share, d.bled_share);
  EXPECT_DOUBLE_EQ(b.shadow_side.erosion_px, 0.0);
  EXPECT_DOUBLE_EQ(b.edge_side.bleed_px, 0.0);
  EXPECT_DOUBLE_EQ(b.edge_side.erosion_px, d.right_erosion);
  EXPECT_DOUBLE_EQ(b.edge_side.bled_share, 0.0);
}

TEST(SilhouetteBleed, MirroredImageSwapsTheSides) {
  Drawn d = Draw(1.5f);
  Drawn mirrored = d;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      mirrored.depth_m[v * kWidth + u] = d.depth_m[v * kWidth + kWidth - 1 - u];
      mirrored.mask[v * kWidth + u] = d.mask[v * kWidth + kWidth - 1 - u];
    }
  }
  const SilhouetteBleed b =
      MeasureSilhouetteBleed(mirrored.depth_m, kWidth, kHeight, mirrored.mask);
  EXPECT_DOUBLE_EQ(b.edge_side.bleed_px, d.left_bleed);
  EXPECT_DOUBLE_EQ(b.shadow_side.erosion_px, d.right_erosion);
}

TEST(SilhouetteBleed, NoStepBehindTheObjectOrNoRoomIsNotMeasured) {
  // The background 2 cm behind: below min_step_m, no end counts.
  Drawn d = Draw(1.02f);
  SilhouetteBleed b = MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask);
  EXPECT_EQ(b.shadow_side.ends, 0);
  EXPECT_EQ(b.edge_side.ends, 0);
  EXPECT_TRUE(std::isnan(b.shadow_side.bleed_px));
  EXPECT_TRUE(std::isnan(b.edge_side.erosion_px));
  // Another object's neighbourhood on the left: the left ends are left out, the right ones stay.
  d = Draw(1.5f);
  std::vector<uint8_t> excluded(kWidth * kHeight, 0);
  for (int v = 0; v < kHeight; ++v) excluded[v * kWidth + kLeft - 20] = 1;
  b = MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask, {}, excluded);
  EXPECT_EQ(b.shadow_side.ends, 0);
  EXPECT_EQ(b.edge_side.ends, kBottom - kTop + 1);
  // Runs shorter than min_run_px (a thin part) are left out.
  SilhouetteBleedOptions o;
  o.min_run_px = kRight - kLeft + 2;
  b = MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask, o);
  EXPECT_EQ(b.shadow_side.ends + b.edge_side.ends, 0);
}

TEST(SilhouetteBleed, BadOptionsAndSizesNameTheirKey) {
  const Drawn d = Draw(1.5f);
  auto message = [&](const SilhouetteBleedOptions& o) {
    try {
      MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  SilhouetteBleedOptions o;
  o.depth_tolerance_m = 0;
  EXPECT_NE(message(o).find("silhouette_bleed.depth_tolerance_m"), std::string::npos);
  o = {};
  o.reference_px = 2;
  EXPECT_NE(message(o).find("silhouette_bleed.reference_px"), std::string::npos);
  o = {};
  o.min_run_px = o.reference_px - 1;
  EXPECT_NE(message(o).find("silhouette_bleed.min_run_px"), std::string::npos);
  o = {};
  o.background_from_px = o.max_px;
  EXPECT_NE(message(o).find("silhouette_bleed.background_from_px"), std::string::npos);
  o = {};
  o.background_to_px = o.background_from_px + 1;
  EXPECT_NE(message(o).find("silhouette_bleed.background_to_px"), std::string::npos);
  o = {};
  o.min_step_m = std::nan("");
  EXPECT_NE(message(o).find("silhouette_bleed.min_step_m"), std::string::npos);
  EXPECT_THROW(MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight - 1, d.mask), InputError);
  EXPECT_THROW(
      MeasureSilhouetteBleed(d.depth_m, kWidth, kHeight, d.mask, {}, std::vector<uint8_t>(3, 0)),
      InputError);
}

}  // namespace
}  // namespace mmh::sim
