// The error-structure statistics against images built with known missing runs and known
// residual correlation.
#include "sim/error_structure.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/error.h"

namespace mmh::sim {
namespace {

constexpr int kWidth = 320, kHeight = 240;

TEST(ErrorStructure, MissingRunsAreClassifiedByTheirNeighbours) {
  // A wall at 2 m; in each row a near board (1 m) over columns [100, 160) with a 6-px hole left
  // of it (shadow: nearer on the right) and a 3-px hole right of it (edge); a 10-px hole inside
  // the wall (low signal); a hole at the left border; rows 200+ at 3.8 m with a hole (range).
  std::vector<float> depth(kWidth * kHeight, 2.0f);
  for (int v = 0; v < kHeight; ++v) {
    float* row = &depth[v * kWidth];
    if (v >= 200) {
      for (int u = 0; u < kWidth; ++u) row[u] = 3.8f;
      for (int u = 50; u < 54; ++u) row[u] = 0;
      continue;
    }
    for (int u = 100; u < 160; ++u) row[u] = 1.0f;
    for (int u = 94; u < 100; ++u) row[u] = 0;
    for (int u = 160; u < 163; ++u) row[u] = 0;
    for (int u = 250; u < 260; ++u) row[u] = 0;
    for (int u = 0; u < 2; ++u) row[u] = 0;
  }
  const ErrorStructure s = AnalyseErrorStructure(depth, kWidth, kHeight, PinholeIntrinsics(),
                                                 KinectCalibration(), AxialNoiseModel());
  const double pixels = kWidth * kHeight;
  EXPECT_DOUBLE_EQ(s.missing_shadow, 200 * 6 / pixels);
  EXPECT_DOUBLE_EQ(s.missing_edge, 200 * 3 / pixels);
  EXPECT_DOUBLE_EQ(s.missing_low_signal, 200 * 10 / pixels);
  EXPECT_DOUBLE_EQ(s.missing_border, 200 * 2 / pixels);
  EXPECT_DOUBLE_EQ(s.missing_range, 40 * 4 / pixels);
  EXPECT_DOUBLE_EQ(s.shadow_band_px, 6);
  EXPECT_DOUBLE_EQ(s.edge_band_px, 3);
  // The bands run the whole 200 rows (column runs of 200): across them nearly their row runs.
  EXPECT_NEAR(s.shadow_band_across_px, 6 / std::sqrt(1 + 36.0 / (200 * 200)), 1e-5);
  EXPECT_NEAR(s.edge_band_across_px, 3 / std::sqrt(1 + 9.0 / (200 * 200)), 1e-5);
}

// The width across a band is its perpendicular width whatever its slant; brute force against
// the formula on bands drawn at several angles.
TEST(ErrorStructure, BandWidthsAcrossDoNotDependOnTheBandsSlant) {
  // A band of 4 px across, drawn as the pixels within 2 px of a line through the image's
  // centre at angle t (a wall at 2 m elsewhere): along rows its runs are about 4 / |sin t|, along
  // columns 4 / |cos t|.
  for (const double degrees : {90.0, 60.0, 45.0, 30.0, 10.0, 0.0}) {
    const double t = degrees * M_PI / 180;
    std::vector<float> depth(kWidth * kHeight, 2.0f);
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const double x = u - (kWidth - 1) / 2.0, y = v - (kHeight - 1) / 2.0;
        if (std::abs(-std::sin(t) * x + std::cos(t) * y) < 2.0) depth[v * kWidth + u] = 0;
      }
    }
    const std::vector<float> across = BandWidthsAcross(depth, kWidth, kHeight);
    // Away from the image's sides, where the band is cut short.
    std::vector<double> inner;
    for (int v = 60; v < kHeight - 60; ++v) {
      for (int u = 100; u < kWidth - 100; ++u) {
        if (depth[v * kWidth + u] == 0) inner.push_back(across[v * kWidth + u]);
      }
    }
    ASSERT_FALSE(inner.empty()) << degrees;
    std::sort(inner.begin(), inner.end());
    const double median = inner[inner.size() / 2];
    EXPECT_NEAR(median, 4.0, 0.6) << degrees << " deg";
    // The run along the row alone grows as 1 / sin t: 23 px at 10 deg.
  }
  // Exact values on a small image: a 2 x 3 hole gives 1 / sqrt(1/9 + 1/4) at each pixel; valid
  // pixels 0; a hole through the whole image counts the image's side as its end.
  std::vector<float> small(5 * 4, 1.0f);
  for (int v = 1; v < 3; ++v) {
    for (int u = 1; u < 4; ++u) small[v * 5 + u] = 0;
  }
  const std::vector<float> w = BandWidthsAcross(small, 5, 4);
  EXPECT_FLOAT_EQ(w[1 * 5 + 2], static_cast<float>(1 / std::sqrt(1.0 / 9 + 1.0 / 4)));
  EXPECT_EQ(w[0], 0.0f);
  EXPECT_THROW(BandWidthsAcross(small, 4, 4), InputError);
}

TEST(ErrorStructure, ResamplingKeepsEachRaysDepth) {
  // A 64 x 48 image at f 50 whose depth encodes the ray (1 + column + 100 row), seen through a
  // camera of twice the focal length and the same size: each of its pixels shows the source
  // pixel nearest its ray, the middle half of the source twice as large.
  const PinholeIntrinsics from{64, 48, 50.0, 50.0, 31.5, 23.5};
  const PinholeIntrinsics to{64, 48, 100.0, 100.0, 31.5, 23.5};
  std::vector<float> depth(64 * 48);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) depth[v * 64 + u] = 1.0f + u + 100.0f * v;
  }
  const std::vector<float> out = ResampleDepthNearest(depth, from, to);
  ASSERT_EQ(out.size(), depth.size());
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      const long x = std::lround(31.5 + (u - 31.5) / 2), y = std::lround(23.5 + (v - 23.5) / 2);
      ASSERT_EQ(out[v * 64 + u], depth[y * 64 + x]) << u << "," << v;
    }
  }
  // The other way the wider view reaches beyond the source: 0 (missing) there.
  const std::vector<float> wide = ResampleDepthNearest(depth, to, from);
  EXPECT_EQ(wide[0], 0.0f);
  EXPECT_EQ(wide[24 * 64 + 32], depth[std::lround(23.5 + 2 * 0.5) * 64 + std::lround(31.5 + 2 * 0.5)]);
  EXPECT_THROW(ResampleDepthNearest(depth, from, PinholeIntrinsics{64, 48, 0.0, 50.0, 31.5, 23.5}),
               InputError);
  EXPECT_THROW(ResampleDepthNearest(std::vector<float>(10), from, to), InputError);
}

// A tilted plane plus noise: white, or averaged over 3 x 3 pixels (neighbours share 6 of 9
// terms horizontally and vertically: rho(1) = 2/3, rho(2) = 1/3, rho(3) = 0).
std::vector<float> NoisyPlane(bool smoothed, double sigma) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, sigma);
  std::vector<double> white((kWidth + 2) * (kHeight + 2));
  for (double& x : white) x = normal(rng);
  std::vector<float> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double e = white[(v + 1) * (kWidth + 2) + u + 1];
      if (smoothed) {
        e = 0;
        for (int j = 0; j < 3; ++j) {
          for (int i = 0; i < 3; ++i) e += white[(v + j) * (kWidth + 2) + u + i];
        }
        e /= 3.0;  // 9 terms of variance sigma^2, divided by 3: variance sigma^2
      }
      depth[v * kWidth + u] = static_cast<float>(1.5 + 0.0004 * u - 0.0003 * v + e);
    }
  }
  return depth;
}

// The expected residual covariance of an n x n window after the plane fit, (I - H) S (I - H),
// with H the fit's hat matrix and S(a, b) = covariance(|du|, |dv|) of the noise.
Eigen::MatrixXd FittedResidualCovariance(int n, double (*covariance)(int du, int dv)) {
  Eigen::MatrixXd design(n * n, 3), cov(n * n, n * n);
  for (int a = 0; a < n * n; ++a) {
    design.row(a) << a % n, a / n, 1.0;
    for (int b = 0; b < n * n; ++b) {
      cov(a, b) = covariance(std::abs(a % n - b % n), std::abs(a / n - b / n));
    }
  }
  const Eigen::MatrixXd residual_maker =
      Eigen::MatrixXd::Identity(n * n, n * n) -
      design * (design.transpose() * design).inverse() * design.transpose();
  return residual_maker * cov * residual_maker;
}

TEST(ErrorStructure, ResidualAutocorrelationOfWhiteAndSmoothedNoise) {
  const ErrorStructure white =
      AnalyseErrorStructure(NoisyPlane(false, 0.003), kWidth, kHeight, PinholeIntrinsics(),
                            KinectCalibration(), AxialNoiseModel());
  const ErrorStructure smooth =
      AnalyseErrorStructure(NoisyPlane(true, 0.003), kWidth, kHeight, PinholeIntrinsics(),
                            KinectCalibration(), AxialNoiseModel());
  ASSERT_EQ(white.autocorrelation.size(), 4u);
  EXPECT_GT(white.patches, 800);
  // The plane fit removes 3 of 81 degrees of freedom: a small negative bias.
  EXPECT_NEAR(white.autocorrelation[0], 0.0, 0.05);
  EXPECT_LT(white.correlation_length_px, 1.0);
  // The oracle for the smoothed noise: the expected residual covariance of a 9 x 9 window,
  // (I - H) S (I - H) with H the plane fit's hat matrix and S the 3 x 3 box's covariance
  // (overlap of the two pixels' boxes / 9), pooled as the estimator pools it.
  constexpr int n = 9;
  const Eigen::MatrixXd r = FittedResidualCovariance(
      n, [](int du, int dv) { return std::max(0, 3 - du) * std::max(0, 3 - dv) / 9.0; });
  for (int k = 1; k <= 3; ++k) {
    double pairs = 0;
    for (int a = 0; a < n * n; ++a) {
      if (a % n + k < n) pairs += r(a, a + k);
      if (a / n + k < n) pairs += r(a, a + k * n);
    }
    const double expected = pairs / (2 * r.trace()) * n / (n - k);
    EXPECT_NEAR(smooth.autocorrelation[k - 1], expected, 0.03) << k;
  }
  // Without the fit: 2/3, 1/3, 0; the fit lowers them (about 0.6, 0.25, -0.05).
  EXPECT_GT(smooth.correlation_length_px, 1.2);
  EXPECT_LT(smooth.correlation_length_px, 2.0);
  // Small-patch noise against the per-pixel model at 1.5 m (sigma_z 3.5 mm, step 6.5 mm):
  // sqrt(3.5^2 + 6.5^2 / 12) = 4.0 mm, so 3 mm of noise is about 0.75 of it.
  EXPECT_NEAR(white.noise_over_model, 0.75, 0.08);
  // The plane is turned about 8 deg from the camera: every patch falls in the first bin.
  EXPECT_EQ(white.noise_over_model_by_incidence[0], white.noise_over_model);
  EXPECT_TRUE(std::isnan(white.noise_over_model_by_incidence[1]));
  EXPECT_TRUE(std::isnan(white.noise_over_model_by_incidence[2]));
  // Every window of the facing wall in the first bin, none in the others.
  EXPECT_EQ(white.patches_by_incidence[0], white.patches);
  EXPECT_EQ(white.patches_by_incidence[1], 0);
  EXPECT_EQ(white.patches_by_incidence[2], 0);
}

// Noise averaged along the rows only (3 pixels side by side): correlated along the rows, not
// along the columns; the pooled value is their mean. Oracle as above, with the 1 x 3 box's
// covariance (overlap / 3 within a row, 0 across rows), each direction's pairs over the trace.
TEST(ErrorStructure, ResidualAutocorrelationAlongRowsAndAlongColumns) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 0.003);
  std::vector<double> white((kWidth + 2) * kHeight);
  for (double& x : white) x = normal(rng);
  std::vector<float> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double e = 0;
      for (int i = 0; i < 3; ++i) e += white[v * (kWidth + 2) + u + i];
      depth[v * kWidth + u] =
          static_cast<float>(1.5 + 0.0004 * u - 0.0003 * v + e / std::sqrt(3.0));
    }
  }
  const ErrorStructure s = AnalyseErrorStructure(depth, kWidth, kHeight, PinholeIntrinsics(),
                                                 KinectCalibration(), AxialNoiseModel());
  ASSERT_EQ(s.autocorrelation_along_rows.size(), 4u);
  ASSERT_EQ(s.autocorrelation_along_columns.size(), 4u);
  constexpr int n = 9;
  const Eigen::MatrixXd r = FittedResidualCovariance(
      n, [](int du, int dv) { return dv == 0 ? std::max(0, 3 - du) / 3.0 : 0.0; });
  for (int k = 1; k <= 2; ++k) {
    double rows = 0, columns = 0;
    for (int a = 0; a < n * n; ++a) {
      if (a % n + k < n) rows += r(a, a + k);
      if (a / n + k < n) columns += r(a, a + k * n);
    }
    EXPECT_NEAR(s.autocorrelation_along_rows[k - 1], rows / r.trace() * n / (n - k), 0.03) << k;
    EXPECT_NEAR(s.autocorrelation_along_columns[k - 1], columns / r.trace() * n / (n - k), 0.03)
        << k;
    EXPECT_NEAR(s.autocorrelation[k - 1],
                (s.autocorrelation_along_rows[k - 1] + s.autocorrelation_along_columns[k - 1]) / 2,
                1e-9);
  }
  EXPECT_GT(s.autocorrelation_along_rows[0], 0.5);
  EXPECT_LT(std::abs(s.autocorrelation_along_columns[0]), 0.1);
}

TEST(ErrorStructure, CauseTableCountsEachClassAgainstEachCause) {
  // One row, 10 pixels: a border run of 2 (the sensor says border), a shadow run of 3 beside a
  // step down from 2 m to 1 m (the sensor: 2 shadow, 1 no match), valid pixels between.
  const std::vector<float> depth = {0, 0, 2, 2, 0, 0, 0, 1, 1, 1};
  const std::vector<MissingClass> classes = ClassifyMissing(depth, 10, 1);
  ASSERT_EQ(classes[0], MissingClass::kBorder);
  ASSERT_EQ(classes[4], MissingClass::kShadow);
  const std::vector<MissingCause> causes = {
      MissingCause::kBorder, MissingCause::kBorder, MissingCause::kValid,   MissingCause::kValid,
      MissingCause::kShadow, MissingCause::kShadow, MissingCause::kNoMatch, MissingCause::kValid,
      MissingCause::kValid,  MissingCause::kValid};
  const std::string table = FormatCauseTable(classes, causes);
  // Rows: class; columns: border, nothing hit, shadow, low signal, no match, ambiguous, range.
  EXPECT_NE(table.find("border             20.00        0.00        0.00        0.00        0.00"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("shadow              0.00        0.00       20.00        0.00       10.00"),
            std::string::npos)
      << table;
  EXPECT_THROW(FormatCauseTable(classes, std::vector<MissingCause>(3)), InputError);
}

// Two frames of a tilted plane sharing a fixed error f (the speckle pattern's) and each with its
// own e (the IR noise's), white with equal variances: E[r_a r_b] / E[r_a^2] = var f / (var f +
// var e) = 1/2, exactly, since the plane fit acts on f and e alike.
TEST(ErrorStructure, TemporalCorrelationIsTheFixedShareOfTheResidualVariance) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 0.002);
  std::vector<float> a(kWidth * kHeight), b(kWidth * kHeight), c(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const double plane = 1.2 + 0.0003 * u + 0.0002 * v, fixed = normal(rng);
      a[v * kWidth + u] = static_cast<float>(plane + fixed + normal(rng));
      b[v * kWidth + u] = static_cast<float>(plane + fixed + normal(rng));
      c[v * kWidth + u] = static_cast<float>(plane + normal(rng));
    }
  }
  const TemporalCorrelation same = AnalyseTemporalCorrelation(a, a, kWidth, kHeight, {});
  EXPECT_DOUBLE_EQ(same.rho, 1.0);
  const int windows = (kWidth / 9) * (kHeight / 9);
  EXPECT_EQ(same.patches, windows);
  const TemporalCorrelation half = AnalyseTemporalCorrelation(a, b, kWidth, kHeight, {});
  EXPECT_NEAR(half.rho, 0.5, 0.03);
  const TemporalCorrelation none = AnalyseTemporalCorrelation(a, c, kWidth, kHeight, {});
  EXPECT_NEAR(none.rho, 0.0, 0.03);
  // A window with a missing pixel in either frame is left out.
  b[5 * kWidth + 5] = 0.0f;
  EXPECT_EQ(AnalyseTemporalCorrelation(a, b, kWidth, kHeight, {}).patches, windows - 1);
  EXPECT_THROW(AnalyseTemporalCorrelation(a, std::vector<float>(10), kWidth, kHeight, {}),
               InputError);
}

// A wall 1 m away seen from two camera positions 3 px apart (b moved along +x by 3 px at 1 m):
// the point seen at pixel u in a is seen at u - 3 in b. Each frame has an error tied to the
// surface S (sd 2 mm: it moves with the wall's points), one tied to the pixel P (1 mm: the
// projected pattern's, which moves with the camera) and its own noise (1 mm). At the same pixels
// the frames share P, var P / var = 1/6; following the surface they share S, 4/6.
TEST(ErrorStructure, SurfaceAlignedDepthFollowsThePointsNotThePixels) {
  std::mt19937 rng(12);
  std::normal_distribution<double> unit(0.0, 0.001);
  const PinholeIntrinsics intrinsics{kWidth, kHeight, 525.0, 525.0, 159.5, 119.5};
  constexpr int kShift = 3;
  // S over the wall's points, indexed by frame a's column (kShift more to the right for b's).
  std::vector<double> surface((kWidth + kShift) * kHeight), pixel(kWidth * kHeight);
  for (double& x : surface) x = 2 * unit(rng);
  for (double& x : pixel) x = unit(rng);
  std::vector<float> a(kWidth * kHeight), b(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const int i = v * kWidth + u, s = v * (kWidth + kShift) + u;
      a[i] = static_cast<float>(1.0 + surface[s] + pixel[i] + unit(rng));
      b[i] = static_cast<float>(1.0 + surface[s + kShift] + pixel[i] + unit(rng));
    }
  }
  const Rigid3 b_T_a(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-kShift / 525.0, 0, 0));
  a[7 * kWidth + 20] = 0.0f;  // missing in a: missing in the aligned frame
  const std::vector<float> aligned = SurfaceAlignedDepth(a, b, kWidth, kHeight, intrinsics, b_T_a);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const int i = v * kWidth + u;
      const float expected = (u < kShift || a[i] == 0.0f) ? 0.0f : b[i - kShift];
      ASSERT_EQ(aligned[i], expected) << u << " " << v;
    }
  }
  EXPECT_NEAR(AnalyseTemporalCorrelation(a, b, kWidth, kHeight, intrinsics).rho, 1.0 / 6, 0.03);
  EXPECT_NEAR(AnalyseTemporalCorrelation(a, aligned, kWidth, kHeight, intrinsics).rho, 4.0 / 6,
              0.03);
  // No motion: the frame itself; a frame of the wrong size is refused.
  EXPECT_EQ(SurfaceAlignedDepth(b, b, kWidth, kHeight, intrinsics, Rigid3()), b);
  EXPECT_THROW(SurfaceAlignedDepth(a, std::vector<float>(10), kWidth, kHeight, intrinsics, b_T_a),
               InputError);
}

// The interior: a 20 x 20 object whose outline ring is missing (the bands) and with three holes
// on its surface, two of them inside the mask shrunk by 2 px (16 x 16 pixels), one on the ring's
// inner side that the shrinking leaves out.
TEST(ErrorStructure, MissingInsideCountsTheHolesOnTheSurfaceNotAtItsOutline) {
  std::vector<float> depth(kWidth * kHeight, 2.0f);
  std::vector<uint8_t> mask(depth.size(), 0);
  for (int v = 40; v < 60; ++v) {
    for (int u = 100; u < 120; ++u) {
      mask[v * kWidth + u] = 1;
      depth[v * kWidth + u] = (v == 40 || v == 59 || u == 100 || u == 119) ? 0.0f : 1.0f;
    }
  }
  depth[50 * kWidth + 110] = 0.0f;
  depth[45 * kWidth + 105] = std::nanf("");
  depth[41 * kWidth + 110] = 0.0f;  // within 2 px of the outline
  NeighbourhoodStructure n;
  MissingInside(depth, kWidth, kHeight, mask, 2, {}, n);
  EXPECT_DOUBLE_EQ(n.interior_pixels, 16.0 * 16.0);
  EXPECT_DOUBLE_EQ(n.interior_missing_share, 2.0 / 256.0);
  // Radius 0: the whole mask, the ring and all three holes.
  MissingInside(depth, kWidth, kHeight, mask, 0, {}, n);
  EXPECT_DOUBLE_EQ(n.interior_pixels, 400.0);
  EXPECT_DOUBLE_EQ(n.interior_missing_share, (76.0 + 3.0) / 400.0);
  // Left out pixels do not count; an object touching the image's side has no interior there.
  std::vector<uint8_t> excluded(depth.size(), 0);
  excluded[50 * kWidth + 110] = 1;
  MissingInside(depth, kWidth, kHeight, mask, 2, excluded, n);
  EXPECT_DOUBLE_EQ(n.interior_pixels, 255.0);
  EXPECT_DOUBLE_EQ(n.interior_missing_share, 1.0 / 255.0);
  std::vector<uint8_t> corner(depth.size(), 0);
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 10; ++u) corner[v * kWidth + u] = 1;
  }
  MissingInside(depth, kWidth, kHeight, corner, 2, {}, n);
  EXPECT_DOUBLE_EQ(n.interior_pixels, 6.0 * 6.0);  // rows and columns 2-7
  // No interior: NaN, and a mask of the wrong size is refused.
  MissingInside(depth, kWidth, kHeight, mask, 10, {}, n);
  EXPECT_DOUBLE_EQ(n.interior_pixels, 0.0);
  EXPECT_TRUE(std::isnan(n.interior_missing_share));
  EXPECT_THROW(MissingInside(depth, kWidth, kHeight, std::vector<uint8_t>(10), 2, {}, n),
               InputError);
}

TEST(ErrorStructure, NeighbourhoodCountsTheObjectsGrownMaskAndTheRunsTouchingIt) {
  // A wall at 2 m; rows [50, 70) hold a near box (1 m) over columns [100, 120) with a 4-px shadow
  // run left of it and a 2-px edge run right of it (in rows 50-59 a 6-px one); a 5-px shadow run
  // of another object far away (columns [250, 255) beside a near board [255, 265)) must not count.
  std::vector<float> depth(kWidth * kHeight, 2.0f);
  std::vector<uint8_t> mask(depth.size(), 0);
  for (int v = 50; v < 70; ++v) {
    float* row = &depth[v * kWidth];
    for (int u = 100; u < 120; ++u) {
      row[u] = 1.0f;
      mask[v * kWidth + u] = 1;
    }
    for (int u = 96; u < 100; ++u) row[u] = 0;
    const int edge = v < 60 ? 6 : 2;
    for (int u = 120; u < 120 + edge; ++u) row[u] = 0;
    for (int u = 255; u < 265; ++u) row[u] = 1.0f;
    for (int u = 250; u < 255; ++u) row[u] = 0;
  }
  // Radius 3: the mask grown to columns [97, 123) and rows [47, 73): 26 x 26 pixels, of which
  // the shadow runs' last 3 columns and the edge runs' first 3 (rows 50-59) or 2 are missing.
  const NeighbourhoodStructure n = AnalyseNeighbourhood(depth, kWidth, kHeight, mask, 3);
  EXPECT_DOUBLE_EQ(n.pixels, 26.0 * 26.0);
  EXPECT_DOUBLE_EQ(n.missing_share, (20.0 * 3 + 10.0 * 3 + 10.0 * 2) / (26.0 * 26.0));
  EXPECT_EQ(n.shadow_runs, 20);  // the far board's runs lie outside
  EXPECT_EQ(n.edge_runs, 20);
  EXPECT_DOUBLE_EQ(n.shadow_band_px, 4.0);  // whole runs, not their part inside
  EXPECT_DOUBLE_EQ(n.edge_band_px, 4.0);    // median of ten 6s and ten 2s
  // Across: the runs are 20 rows tall (column runs of 20, or of 10 where the edge run is 6 wide
  // and the rows 60-69 have no pixel there); pixel medians.
  EXPECT_NEAR(n.shadow_band_across_px, 1 / std::sqrt(1 / 16.0 + 1 / 400.0), 1e-5);
  // Edge pixels: 20 at (6 x 20), 40 at (6 x 10), 20 at (2 x 20); the middle ones are (6 x 10).
  EXPECT_NEAR(n.edge_band_across_px, 1 / std::sqrt(1 / 36.0 + 1 / 100.0), 1e-5);
  // Radius 0: the mask itself, nothing missing in it, but the runs beside it do not touch it.
  const NeighbourhoodStructure inside = AnalyseNeighbourhood(depth, kWidth, kHeight, mask, 0);
  EXPECT_DOUBLE_EQ(inside.pixels, 400.0);
  EXPECT_DOUBLE_EQ(inside.missing_share, 0.0);
  EXPECT_EQ(inside.shadow_runs + inside.edge_runs, 0);
  EXPECT_TRUE(std::isnan(inside.edge_band_px));
  // A radius reaching the image's sides is clipped to it.
  EXPECT_DOUBLE_EQ(AnalyseNeighbourhood(depth, kWidth, kHeight, mask, 1000).pixels,
                   static_cast<double>(kWidth) * kHeight);
  EXPECT_THROW(AnalyseNeighbourhood(depth, kWidth, kHeight, std::vector<uint8_t>(10), 3),
               InputError);
  EXPECT_THROW(AnalyseNeighbourhood(depth, kWidth, kHeight, mask, -1), InputError);
  // Left out: columns [121, 130) of rows [50, 60), where another object would stand. Its 20
  // pixels inside the grown mask do not count, nor do the 6-px edge runs that reach into it; the
  // runs beside it (rows 60-69) still do.
  std::vector<uint8_t> excluded(depth.size(), 0);
  for (int v = 50; v < 60; ++v) {
    for (int u = 121; u < 130; ++u) excluded[v * kWidth + u] = 1;
  }
  const NeighbourhoodStructure away =
      AnalyseNeighbourhood(depth, kWidth, kHeight, mask, 3, {}, excluded);
  EXPECT_DOUBLE_EQ(away.pixels, 26.0 * 26.0 - 20);
  EXPECT_DOUBLE_EQ(away.missing_share, (20.0 * 3 + 10.0 * 1 + 10.0 * 2) / (26.0 * 26.0 - 20));
  EXPECT_EQ(away.shadow_runs, 20);
  EXPECT_EQ(away.edge_runs, 10);
  EXPECT_DOUBLE_EQ(away.edge_band_px, 2.0);
  EXPECT_THROW(AnalyseNeighbourhood(depth, kWidth, kHeight, mask, 3, {}, std::vector<uint8_t>(10)),
               InputError);
  // GrowMask: the square of side 2 r + 1 around each pixel, clipped to the image.
  const std::vector<uint8_t> grown = GrowMask(mask, kWidth, kHeight, 3);
  EXPECT_EQ(std::count(grown.begin(), grown.end(), uint8_t{1}), 26 * 26);
  EXPECT_EQ(grown[47 * kWidth + 97], 1);
  EXPECT_EQ(grown[46 * kWidth + 97], 0);
}

TEST(ErrorStructure, BadInputNamesTheField) {
  ErrorStructureOptions options;
  options.patch_size = 8;
  EXPECT_THROW(options.Validate("x"), InputError);
  EXPECT_THROW(AnalyseErrorStructure(std::vector<float>(10), kWidth, kHeight, PinholeIntrinsics(),
                                     KinectCalibration(), AxialNoiseModel()),
               InputError);
}

}  // namespace
}  // namespace mmh::sim
