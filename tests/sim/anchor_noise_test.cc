// The anchors' noise models (sim/anchor_noise.h) against what their published formulas imply on
// walls: the depth lattice and spread of Barron and Malik's disparity noise, the lateral shift's
// mixing at a depth step, and the simkinect filter's dots and its holes beside a step.
#include "sim/anchor_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "core/error.h"

namespace mmh::sim {
namespace {

constexpr int kWidth = 160, kHeight = 120;

std::vector<float> Wall(double z) { return std::vector<float>(kWidth * kHeight, float(z)); }

// Left half at z_near, right half at z_far.
std::vector<float> Step(double z_near, double z_far) {
  std::vector<float> d(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) d[v * kWidth + u] = u < kWidth / 2 ? z_near : z_far;
  }
  return d;
}

TEST(AnchorNoiseTest, IclNuimPutsAWallOnTheRawLatticeWithBarronAndMaliksSpread) {
  // A wall at 1 m: 35130 / 100 cm = 351.3 raw units; + 1/2 + N(0, 1/6), rounded: raw 351 where
  // n < -1.8, 353 where n > 4.2 (about one pixel in 75 000), else 352; depth 35130 / raw cm. The
  // mean and spread in raw units follow from those probabilities.
  const std::vector<float> out =
      ApplyAnchorNoise(AnchorModel::kIclNuim, Wall(1.0), kWidth, kHeight, 7, 0);
  std::set<long> raws;
  double n = 0, sum = 0, sum2 = 0;
  for (int v = 2; v < kHeight - 2; ++v) {
    for (int u = 2; u < kWidth - 2; ++u) {
      const float z = out[v * kWidth + u];
      ASSERT_GT(z, 0) << u << " " << v;
      const double raw = 351.3 / z;
      EXPECT_NEAR(raw, std::round(raw), 1e-3) << "on the lattice";
      raws.insert(std::lround(raw));
      ++n;
      sum += raw;
      sum2 += raw * raw;
    }
  }
  EXPECT_TRUE(raws.count(351) && raws.count(352));
  EXPECT_LE(raws.size(), 3u);
  const double p351 = 0.5 * std::erfc(1.8 / std::sqrt(2.0));
  const double p353 = 0.5 * std::erfc(4.2 / std::sqrt(2.0));
  const double mean = 352 - p351 + p353;
  const double var = p351 + p353 - (p353 - p351) * (p353 - p351);
  EXPECT_NEAR(sum / n, mean, 0.01);
  EXPECT_NEAR(std::sqrt(sum2 / n - (sum / n) * (sum / n)), std::sqrt(var), 0.02);
}

TEST(AnchorNoiseTest, TheLateralShiftMixesTheTwoSidesOfAStepOnly) {
  AnchorNoiseOptions no_disparity_noise;
  no_disparity_noise.raw_noise_sigma = 0;
  const std::vector<float> out = ApplyAnchorNoise(AnchorModel::kIclNuim, Step(1.0, 2.0), kWidth,
                                                  kHeight, 3, 0, no_disparity_noise);
  // Far from the step every pixel keeps its side's lattice value; within two pixels of it some
  // take values between the two sides (bilinear mixing: flying pixels).
  int mixed_near = 0, mixed_far = 0;
  for (int v = 2; v < kHeight - 2; ++v) {
    for (int u = 2; u < kWidth - 2; ++u) {
      const float z = out[v * kWidth + u];
      const bool mixed = z > 1.01f && z < 1.98f;
      if (std::abs(u - kWidth / 2) <= 2) {
        mixed_near += mixed;
      } else {
        mixed_far += mixed;
      }
    }
  }
  EXPECT_GT(mixed_near, 50);
  EXPECT_EQ(mixed_far, 0);
}

TEST(AnchorNoiseTest, SimKinectKeepsAWallAndLosesABandBesideAStep) {
  // On a flat wall every window passes the filter, so a pixel is valid exactly when a dot lies
  // within the fill radius (3 px: 29 pixels): 1 - 0.89^29 = 96.6 % of them.
  const std::vector<float> wall =
      ApplyAnchorNoise(AnchorModel::kSimKinect, Wall(1.0), kWidth, kHeight, 5, 0);
  int valid = 0, inner = 0;
  for (int v = 8; v < kHeight - 8; ++v) {
    for (int u = 8; u < kWidth - 8; ++u) {
      ++inner;
      valid += wall[v * kWidth + u] > 0;
    }
  }
  EXPECT_NEAR(valid / double(inner), 1 - std::pow(0.89, 29), 0.01);
  // Beside a step of 1 m to 2 m (disparity 43.5 px against 21.75) a window straddling it has a
  // mean between the sides and its dots fail the inlier test: a missing band along the step; away
  // from it only the pixels without a dot in reach (3.4 %).
  const std::vector<float> step =
      ApplyAnchorNoise(AnchorModel::kSimKinect, Step(1.0, 2.0), kWidth, kHeight, 5, 0);
  int band_missing = 0, band = 0, away_missing = 0, away = 0;
  for (int v = 8; v < kHeight - 8; ++v) {
    for (int u = 8; u < kWidth - 8; ++u) {
      const bool missing = !(step[v * kWidth + u] > 0);
      if (std::abs(u - kWidth / 2) <= 2) {
        ++band;
        band_missing += missing;
      } else if (std::abs(u - kWidth / 2) >= 12) {
        ++away;
        away_missing += missing;
      }
    }
  }
  EXPECT_GT(band_missing, 0.5 * band);
  EXPECT_LT(away_missing, 0.05 * away);
}

TEST(AnchorNoiseTest, TheSameSeedAndFrameGiveTheSameBytes) {
  const std::vector<float> a =
      ApplyAnchorNoise(AnchorModel::kSimKinect, Step(0.8, 1.6), kWidth, kHeight, 11, 2);
  EXPECT_EQ(a, ApplyAnchorNoise(AnchorModel::kSimKinect, Step(0.8, 1.6), kWidth, kHeight, 11, 2));
  EXPECT_NE(a, ApplyAnchorNoise(AnchorModel::kSimKinect, Step(0.8, 1.6), kWidth, kHeight, 11, 3));
}

TEST(AnchorNoiseTest, BadInputNamesTheFieldAndTheValue) {
  AnchorNoiseOptions options;
  options.window_px = 8;
  try {
    ApplyAnchorNoise(AnchorModel::kSimKinect, Wall(1.0), kWidth, kHeight, 1, 0, options);
    FAIL() << "an even window was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("anchor.window_px: got 8"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ApplyAnchorNoise(AnchorModel::kIclNuim, Wall(1.0), kWidth, kHeight - 1, 1, 0),
               InputError);
}

}  // namespace
}  // namespace mmh::sim
