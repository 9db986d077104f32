// Tests of sim/sensor_check.h: the estimators recover a known lattice constant and noise on
// synthetic frames, and the real Kinect v1 frames (data/real-rgbd, skipped when absent) follow the
// model's step law.
#include "sim/sensor_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <random>
#include <string>

#include "core/error.h"
#include "core/image_io.h"

namespace mmh::sim {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kRealRgbd = "/work/shared/data/real-rgbd";
constexpr int kWidth = 640, kHeight = 480;

// Ten horizontal bands of 48 rows at 0.8, 1.1, ..., 3.5 m, each tilted by +-8 % across the image
// (a few degrees: the patches stay well under 60 degrees incidence) so that every band covers
// many lattice depths. `perturb` adds noise to the true depth; `lattice` snaps to the Kinect
// lattice; `storage_quantum_m` rounds as a file would (0: no rounding).
std::vector<float> BandScene(const std::function<double(double)>& perturb, bool lattice,
                             double storage_quantum_m) {
  const KinectCalibration calibration;
  std::vector<float> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    const double z0 = 0.8 + 0.3 * (v / 48);
    for (int u = 0; u < kWidth; ++u) {
      double z = perturb(z0 * (1.0 + 0.08 * (u - 320) / 320.0));
      if (lattice) z = DepthFromRaw(RawFromDepth(z, calibration), calibration);
      if (storage_quantum_m > 0) z = std::round(z / storage_quantum_m) * storage_quantum_m;
      depth[v * kWidth + u] = static_cast<float>(z);
    }
  }
  return depth;
}

double ModelK() { return 1.0 / KinectCalibration().lattice_constant(); }

TEST(SensorCheckTest, MissingFraction) {
  EXPECT_EQ(MissingFraction({}), 0.0);
  EXPECT_EQ(MissingFraction({0.0f, 1.0f, NAN, -1.0f, 2.0f, INFINITY, 3.0f, 4.0f}), 0.5);
}

TEST(SensorCheckTest, StepLawOfAnExactLattice) {
  const auto depth = BandScene([](double z) { return z; }, true, 0.0);
  const DepthStepLaw law = FitDepthStepLaw(depth, SensorCheckOptions());
  EXPECT_EQ(law.depth_quantum_m, 0.0);  // float lattice depths are no multiples of a round unit
  EXPECT_NEAR(law.k / ModelK(), 1.0, 1e-4);
  EXPECT_NEAR(law.model_k, 1.0 / 348.0, 1e-12);
  EXPECT_GT(law.fundamental_fraction, 0.9);
  EXPECT_GT(law.bins.size(), 10u);
  for (const auto& bin : law.bins) {
    if (bin.pairs < 10) continue;
    // A dense bin's median step is one lattice step at its depth.
    EXPECT_NEAR(bin.median_step_m / bin.model_step_m, 1.0, 0.02) << bin.z_min_m;
    EXPECT_EQ(bin.fundamental_fraction, 1.0);
  }
}

TEST(SensorCheckTest, StepLawWithNoiseAndTumStorage) {
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  const AxialNoiseModel noise;
  const auto depth =
      BandScene([&](double z) { return z + noise.Sigma(z, 0.0) * normal(rng); }, true, 0.0002);
  SensorCheckOptions options;
  const DepthStepLaw law = FitDepthStepLaw(depth, options);
  EXPECT_DOUBLE_EQ(law.depth_quantum_m, 0.0002);
  EXPECT_NEAR(law.k / ModelK(), 1.0, 0.01);
  // A lattice of another sensor is recovered as well (the estimator does not assume the model).
  KinectCalibration other;
  other.ir_focal_length = 560;
  const KinectCalibration calibration;
  std::vector<float> scaled(depth.size());
  for (size_t i = 0; i < depth.size(); ++i) {
    // z' = z * 560 / 580 maps the lattice C / (offset - raw) onto C' / (offset - raw).
    scaled[i] =
        static_cast<float>(depth[i] * other.lattice_constant() / calibration.lattice_constant());
  }
  options.depth_quantum_m = 1e-9;  // no storage rounding after the scaling
  EXPECT_NEAR(FitDepthStepLaw(scaled, options).k * other.lattice_constant(), 1.0, 0.01);
}

TEST(SensorCheckTest, SparseValuesUseTheSmallestCommonStep) {
  const KinectCalibration calibration;
  // Every lattice depth of raw 600..899 (0.71-1.8 m), then only every other one up to raw 1000
  // (to 3.8 m) and a few isolated far values: adjacent distinct values are 1, 2 and many steps
  // apart.
  std::vector<float> depth(kWidth * kHeight, 0.0f);
  size_t pixel = 0;
  auto put = [&](int raw) { depth[pixel++] = static_cast<float>(DepthFromRaw(raw, calibration)); };
  for (int raw = 600; raw < 900; ++raw) put(raw);
  for (int raw = 900; raw <= 1000; raw += 2) put(raw);
  for (int raw : {1020, 1040, 1050}) put(raw);
  const DepthStepLaw law = FitDepthStepLaw(depth, SensorCheckOptions());
  EXPECT_NEAR(law.k / ModelK(), 1.0, 1e-4);
  EXPECT_NEAR(law.fundamental_k / ModelK(), 1.0, 1e-4);
  // 300 one-step pairs (899 -> 900 included) and 50 two-step pairs are fitted; the gaps of 20,
  // 20 and 10 steps are left out.
  EXPECT_EQ(law.pairs, 353);
  EXPECT_EQ(law.pairs_fitted, 350);
  EXPECT_DOUBLE_EQ(law.fundamental_fraction, 300.0 / 350.0);
}

TEST(SensorCheckTest, PatchNoiseRecoversSigma) {
  std::mt19937 rng(2);
  std::normal_distribution<double> normal;
  constexpr double kSigma = 0.002;
  const auto depth = BandScene([&](double z) { return z + kSigma * normal(rng); }, false, 0.0);
  int patches = 0;
  const auto bins = EstimatePatchNoise(depth, kWidth, kHeight, SensorCheckOptions(), &patches);
  EXPECT_GT(patches, 3000);
  int checked = 0;
  for (const auto& bin : bins) {
    if (bin.patches < 100) continue;
    ++checked;
    EXPECT_NEAR(bin.median_residual_m / kSigma, 1.0, 0.03) << bin.z_min_m;
  }
  EXPECT_GE(checked, 6);
}

TEST(SensorCheckTest, IncidenceAnglesOfAFrontoParallelPlane) {
  // A plane at constant depth is seen at the angle between each pixel's ray and the optical axis.
  const std::vector<float> depth(kWidth * kHeight, 2.0f);
  const SensorCheckOptions options;
  const auto bins = EstimatePatchNoise(depth, kWidth, kHeight, options);
  ASSERT_EQ(bins.size(), 1u);
  std::vector<double> angles;
  const auto& k = options.intrinsics;
  for (int v0 = 4; v0 + 4 < kHeight; v0 += 9) {
    for (int u0 = 4; u0 + 4 < kWidth; u0 += 9) {
      angles.push_back(std::atan(std::hypot((u0 - k.cx) / k.fx, (v0 - k.cy) / k.fy)) * 180 / M_PI);
    }
  }
  std::sort(angles.begin(), angles.end());
  ASSERT_EQ(bins[0].patches, static_cast<int>(angles.size()));
  const size_t n = angles.size();
  const double median = n % 2 ? angles[n / 2] : 0.5 * (angles[n / 2 - 1] + angles[n / 2]);
  EXPECT_NEAR(bins[0].median_incidence_deg, median, 1e-6);
  EXPECT_EQ(bins[0].median_residual_m, 0.0);
  // The model at the median angle (all under 60 degrees: no grazing term).
  EXPECT_DOUBLE_EQ(bins[0].model_sigma_m, options.noise.Sigma(2.0, 0.0));
}

TEST(SensorCheckTest, PatchNoiseOfTheModelIncludesQuantisation) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const AxialNoiseModel noise;
  const auto depth =
      BandScene([&](double z) { return z + noise.Sigma(z, 0.0) * normal(rng); }, true, 0.0);
  const auto bins = EstimatePatchNoise(depth, kWidth, kHeight, SensorCheckOptions());
  int checked = 0;
  for (const auto& bin : bins) {
    if (bin.patches < 100) continue;
    ++checked;
    // sigma_z and the lattice step are of the same size here: the residual is their sum in
    // quadrature, clearly above sigma_z alone.
    EXPECT_NEAR(bin.median_residual_m / bin.model_total_m, 1.0, 0.1) << bin.z_min_m;
    EXPECT_GT(bin.median_residual_m, 1.05 * bin.model_sigma_m) << bin.z_min_m;
  }
  EXPECT_GE(checked, 6);
}

TEST(SensorCheckTest, SteepPlanesAreLeftOutOfTheNoise) {
  // A floor seen at grazing incidence: z = exp(0.02 v) rises 2 % per row, dz/dy = 0.02 fy =
  // 10.5, about 85 degrees; the principal point near those rows keeps the rays close to the axis.
  std::vector<float> depth(kWidth * kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) depth[v * kWidth + u] = static_cast<float>(std::exp(0.02 * v));
  }
  SensorCheckOptions options;
  options.intrinsics.cy = 60;
  int patches = -1;
  EstimatePatchNoise(depth, kWidth, kHeight, options, &patches);
  EXPECT_EQ(patches, 0);
  options.max_incidence_deg = 90;
  const auto bins = EstimatePatchNoise(depth, kWidth, kHeight, options, &patches);
  EXPECT_EQ(patches, 12 * 71);  // the window rows up to 10 m
  EXPECT_GT(bins.back().median_incidence_deg, 80.0);
}

TEST(SensorCheckTest, RawDisparity) {
  const RawDisparityStatistics raw = AnalyseRawDisparity({2047, 700, 701, 703, 701, 2047}, {});
  EXPECT_EQ(raw.valid_pixels, 4);
  EXPECT_EQ(raw.distinct_values, 3);
  EXPECT_EQ(raw.min_raw, 700);
  EXPECT_EQ(raw.max_raw, 703);
  EXPECT_EQ(raw.unit_step_fraction, 0.5);
  EXPECT_EQ(raw.median_step, 1.5);
  EXPECT_EQ(raw.implied_k, 1.5 / 351.3);
  const auto z = DepthMetresFromNyuRaw({2047, 0, 1092, 1093});
  EXPECT_EQ(z[0], 0.0f);
  EXPECT_EQ(z[1], static_cast<float>(351.3 / 1092.5));
  EXPECT_EQ(z[2], static_cast<float>(351.3 / 0.5));
  EXPECT_EQ(z[3], 0.0f);
}

TEST(SensorCheckTest, StatisticsJsonAndTable) {
  const auto depth = BandScene([](double z) { return z; }, true, 0.0002);
  SensorStatistics a = ComputeSensorStatistics("model", depth, kWidth, kHeight);
  SensorStatistics b = ComputeSensorStatistics("copy", depth, kWidth, kHeight, {}, nullptr);
  const nlohmann::json json = ToJson(a);
  EXPECT_EQ(json["name"], "model");
  EXPECT_EQ(json["missing_fraction"], 0.0);
  EXPECT_NEAR(json["step_law"]["k_over_model"].get<double>(), 1.0, 0.01);
  EXPECT_FALSE(json.contains("raw"));
  const std::string table = FormatSensorTable({a, b});
  EXPECT_THAT(table, HasSubstr("model"));
  EXPECT_THAT(table, HasSubstr("copy"));
  EXPECT_THAT(table, HasSubstr("k / model k"));
  EXPECT_THAT(table, HasSubstr("step 1.00-1.25 m"));
  EXPECT_THAT(table, HasSubstr("noise 1.00-1.25 m"));
  try {
    ComputeSensorStatistics("bad", depth, 10, 10);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("bad, depth: got 307200 pixels, expected 10x10"));
  }
  SensorCheckOptions options;
  options.patch_size = 8;
  EXPECT_THROW(ComputeSensorStatistics("x", depth, kWidth, kHeight, options), InputError);
}

// --- The real Kinect v1 frames ----------------------------------------------------------------

TEST(SensorCheckRealDataTest, StepLawsAgreeWithTheModel) {
  if (!fs::exists(kRealRgbd / "TUM_depth.png")) GTEST_SKIP() << "no " << kRealRgbd;
  const DepthImage tum = ReadDepthPng16(kRealRgbd / "TUM_depth.png");
  const DepthImage nyu_raw = ReadNyuRawDisparity(kRealRgbd / "NYU_depth.pgm");
  const DepthImage sun = ReadSunDepth(kRealRgbd / "SUN_depth.png");
  const SensorCheckOptions options;
  const SensorStatistics tum_stats = ComputeSensorStatistics(
      "TUM real", DepthMetresFromUnits(tum.values, 1.0 / 5000), tum.width, tum.height, options);
  const SensorStatistics nyu_stats =
      ComputeSensorStatistics("NYU real", DepthMetresFromNyuRaw(nyu_raw.values), nyu_raw.width,
                              nyu_raw.height, options, &nyu_raw.values);
  const SensorStatistics sun_stats = ComputeSensorStatistics(
      "SUN real", DepthMetresFromUnits(sun.values, 1e-3), sun.width, sun.height, options);
  std::mt19937 rng(4);
  std::normal_distribution<double> normal;
  const SensorStatistics model_stats = ComputeSensorStatistics(
      "model (bands)",
      BandScene([&](double z) { return z + options.noise.Sigma(z, 0) * normal(rng); }, true,
                0.0002),
      kWidth, kHeight, options);
  std::cout << FormatSensorTable({tum_stats, nyu_stats, sun_stats, model_stats});

  // data/README.md: 19 % and 7 % missing.
  EXPECT_NEAR(tum_stats.missing_fraction, 0.19, 0.02);
  EXPECT_NEAR(nyu_stats.missing_fraction, 0.07, 0.02);
  // The model's k = 1 / (8 * 580 * 0.075) within 10 %.
  const double model_k = ModelK();
  EXPECT_NEAR(tum_stats.step_law.k / model_k, 1.0, 0.1);
  EXPECT_NEAR(nyu_stats.step_law.k / model_k, 1.0, 0.1);
  // NYU's depths come from its raw integers through z = 351.3 / (1092.5 - raw): the lattice
  // constant is 351.3 exactly, and adjacent raw values are one unit apart.
  EXPECT_NEAR(nyu_stats.step_law.k * kNyuDepthNumerator, 1.0, 1e-4);
  EXPECT_GT(nyu_stats.raw.unit_step_fraction, 0.95);
  EXPECT_EQ(nyu_stats.raw.median_step, 1.0);
  // TUM stores OpenNI's millimetres times 5: a 1 mm quantum.
  EXPECT_DOUBLE_EQ(tum_stats.step_law.depth_quantum_m, 0.001);
  // data/README.md: steps near 2.4 m are 16-18 mm.
  const double tum_step_24 = tum_stats.step_law.k * 2.4 * 2.4;
  EXPECT_GT(tum_step_24, 0.016);
  EXPECT_LT(tum_step_24, 0.018);
  // The SUN RGB-D frame is a Kinect v1 capture too.
  EXPECT_NEAR(sun_stats.step_law.k / model_k, 1.0, 0.1);
}

}  // namespace
}  // namespace mmh::sim
