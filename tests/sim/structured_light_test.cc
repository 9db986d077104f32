// The structured-light sensor mode against analytic geometry: planes at known depths, the
// materials that make the pattern vanish, the IR shadow, the block-matching signature (spatially
// correlated errors), determinism.
#include "sim/structured_light.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "core/error.h"
#include "sim/error_structure.h"
#include "sim/kinect_sensor.h"
#include "tests/sim/sensor_modes.h"
#include "tests/test_meshes.h"
#include "tests/test_util.h"

namespace mmh::sim {
namespace {

using ::testing::HasSubstr;

using test_util::ErrorOf;
using test_util::Quad;

// A wall facing the camera (camera at the origin looking along +z) at depth z.
Rigid3 WallAt(double z) {
  return Rigid3(
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()),
      Eigen::Vector3d(0, 0, z));
}

using test_modes::Statistical;

KinectSensorOptions StructuredLight() {
  KinectSensorOptions options;
  options.mode = SensorMode::kStructuredLight;
  return options;
}

struct Stats {
  int valid = 0, missing = 0;
  double mean_error = 0, rms_error = 0;
};
// Over the image's centre (a 400 x 300 window), against the true depth z.
Stats CentreStats(const RgbdFrame& frame, double z) {
  Stats s;
  const int w = frame.depth_intrinsics.width;
  for (int v = 90; v < 390; ++v) {
    for (int u = 120; u < 520; ++u) {
      const uint16_t d = frame.depth[v * w + u];
      if (d == 0) {
        ++s.missing;
        continue;
      }
      const double e = d * frame.depth_scale - z;
      ++s.valid;
      s.mean_error += e;
      s.rms_error += e * e;
    }
  }
  if (s.valid > 0) {
    s.mean_error /= s.valid;
    s.rms_error = std::sqrt(s.rms_error / s.valid);
  }
  return s;
}

RgbdFrame RenderWall(double z, const SurfaceMaterial& material, const KinectSensorOptions& options,
                     int index = 0) {
  RayScene scene;
  const uint32_t wall = scene.AddStatic("wall", Quad(20, 20), WallAt(z));
  scene.SetMaterial(wall, material);
  scene.Commit();
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  return sensor.Render(index, RenderMode::kFull);
}

// A wall of albedo 0.6 at 0.75 m turned turn_deg about the image's vertical, one full frame.
RgbdFrame RenderTurnedWall(double turn_deg, const KinectSensorOptions& options) {
  RayScene scene;
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(turn_deg * M_PI / 180, Eigen::Vector3d::UnitY()));
  const Rigid3 wall_pose(turn * WallAt(0.0).rotation, Eigen::Vector3d(0, 0, 0.75));
  scene.SetMaterial(scene.AddStatic("wall", Quad(4, 4), wall_pose), SurfaceMaterial{0.6, 0.0});
  scene.Commit();
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  return sensor.Render(0, RenderMode::kFull);
}

// The small-patch noise over the per-pixel model in the image's centre (240 x 200 px), with at
// least 400 planar windows.
double CentreNoiseOverModel(const RgbdFrame& frame, const KinectSensorOptions& options) {
  const PinholeIntrinsics& in = frame.depth_intrinsics;
  std::vector<float> depth_m(frame.depth.size(), 0.0f);
  for (int v = 140; v < 340; ++v) {
    for (int u = 200; u < 440; ++u) {
      const size_t p = static_cast<size_t>(v) * in.width + u;
      depth_m[p] = static_cast<float>(frame.depth[p] * frame.depth_scale);
    }
  }
  const ErrorStructure e =
      AnalyseErrorStructure(depth_m, in.width, in.height, in, options.calibration, options.axial);
  EXPECT_GT(e.patches, 400);
  return e.noise_over_model;
}

TEST(StructuredLight, WallsAtOneToThreeMetresMatchTheirDepthOnTheLattice) {
  const KinectCalibration calibration;
  for (const double z : {0.8, 1.2, 2.0, 3.0}) {
    const RgbdFrame frame = RenderWall(z, SurfaceMaterial{0.7, 0.0}, StructuredLight());
    const Stats s = CentreStats(frame, z);
    const double step = LatticeStep(z, calibration);
    SCOPED_TRACE(z);
    EXPECT_GT(s.valid, 0.97 * (s.valid + s.missing));
    // Sub-pixel matching: biased by less than one lattice step (1/8 px of disparity; a
    // fronto-parallel wall has one disparity fraction everywhere, so the parabola's pull towards
    // whole pixels, "pixel locking", does not average out: 0.51 steps at 0.8 m, where d = 54.4
    // px), spread of a few steps (Kinect v1 at 1-3 m: 1-2 steps, Khoshelham and Elberink 2012).
    EXPECT_LT(std::abs(s.mean_error), step) << s.mean_error << " " << s.rms_error;
    EXPECT_LT(s.rms_error, 3.0 * step) << s.mean_error << " " << s.rms_error;
    EXPECT_GT(s.rms_error, 0.1 * step) << s.mean_error << " " << s.rms_error;
    // Every depth on the lattice.
    for (uint16_t d : frame.depth) {
      if (d == 0) continue;
      const int raw = RawFromDepth(d * frame.depth_scale, calibration);
      ASSERT_NEAR(d * frame.depth_scale, DepthFromRaw(raw, calibration), 1e-4);
    }
  }
}

TEST(StructuredLight, DarkFarAndMirrorSurfacesLoseThePattern) {
  const KinectSensorOptions options = StructuredLight();
  // Black matte at 3.5 m: below the sensor noise.
  EXPECT_GT(CentreStats(RenderWall(3.5, SurfaceMaterial{0.02, 0.0}, options), 3.5).missing,
            0.9 * 400 * 300);
  // The same grey wall returns less and less with distance.
  const double near =
      CentreStats(RenderWall(1.5, SurfaceMaterial{0.15, 0.0}, options), 1.5).missing;
  const double far = CentreStats(RenderWall(3.8, SurfaceMaterial{0.15, 0.0}, options), 3.8).missing;
  EXPECT_LT(near, 0.05 * 400 * 300);
  EXPECT_GT(far, near + 0.2 * 400 * 300);
  // A mirror facing the camera at 1 m saturates the IR image where it returns the projector.
  EXPECT_GT(CentreStats(RenderWall(1.0, SurfaceMaterial{0.5, 1.0}, options), 1.0).missing,
            0.5 * 400 * 300);
}

// Missing share of the centre window's left and right halves (columns 120-319, 320-519).
std::pair<double, double> MissingByHalf(const RgbdFrame& frame) {
  int missing[2] = {0, 0};
  const int w = frame.depth_intrinsics.width;
  for (int v = 90; v < 390; ++v) {
    for (int u = 120; u < 520; ++u) missing[u >= 320] += frame.depth[v * w + u] == 0;
  }
  return {missing[0] / (200.0 * 300), missing[1] / (200.0 * 300)};
}

TEST(StructuredLight, PrintedFacesFollowTheirColour) {
  // One wall at 1.5 m, printed black on one half and white on the other (one object, so the
  // albedo is per face).
  TriangleMesh wall, black = Quad(10, 20), white = Quad(10, 20);
  black.face_colors.setConstant(0);
  white.face_colors.setConstant(255);
  AppendMesh(black, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-5, 0, 0)), &wall);
  AppendMesh(white, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(5, 0, 0)), &wall);
  auto render = [&](double contrast) {
    RayScene scene;
    const uint32_t object = scene.AddStatic("wall", wall, WallAt(1.5));
    scene.SetMaterial(object, SurfaceMaterial{0.5, 0.0, contrast});
    scene.Commit();
    KinectSensor sensor(StructuredLight(), &scene, Rigid3::Identity());
    return MissingByHalf(sensor.Render(0, RenderMode::kFull));
  };
  // Without contrast both halves are the same grey wall and match.
  const auto [plain_left, plain_right] = render(0.0);
  EXPECT_LT(plain_left, 0.05);
  EXPECT_LT(plain_right, 0.05);
  // Fully printed: the black half returns no pattern, the white one the whole albedo.
  const auto [left, right] = render(1.0);
  EXPECT_GT(std::max(left, right), 0.9) << left << " " << right;
  EXPECT_LT(std::min(left, right), 0.05) << left << " " << right;
  try {
    SurfaceMaterial{0.5, 0.0, 1.5}.Validate("scene.objects[0].material");
    FAIL() << "accepted a contrast of 1.5";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scene.objects[0].material.colour_contrast"));
  }
}

// A translucent wall (SurfaceMaterial::subsurface_mm) returns each dot blurred: its windows
// correlate less sharply with the reference and more of them fail; an opaque wall's frame is
// the same with or without the blur's machinery (the scene has a translucent object elsewhere).
TEST(StructuredLight, TranslucentSurfacesBlurTheDotsAndLoseMatches) {
  auto render = [&](double subsurface_mm) {
    SurfaceMaterial material{0.6, 0.0};
    material.subsurface_mm = subsurface_mm;
    return CentreStats(RenderWall(0.6, material, StructuredLight()), 0.6).missing / (400.0 * 300.0);
  };
  const double opaque = render(0), slight = render(0.3), foam = render(1.5);
  EXPECT_LT(opaque, 0.01);
  EXPECT_LT(slight, 0.02);
  EXPECT_GT(foam, opaque + 0.05) << opaque << " " << slight << " " << foam;
  // An opaque wall beside a translucent box far off to the side: the same bytes as alone.
  RayScene scene;
  scene.SetMaterial(scene.AddStatic("wall", Quad(20, 20), WallAt(1.5)), SurfaceMaterial{0.6, 0.0});
  SurfaceMaterial translucent{0.6, 0.0};
  translucent.subsurface_mm = 2.0;
  scene.SetMaterial(scene.AddStatic("box", Quad(0.1, 0.1),
                                    Rigid3(WallAt(1.0).rotation, Eigen::Vector3d(50, 0, 1.0))),
                    translucent);
  scene.Commit();
  KinectSensor sensor(StructuredLight(), &scene, Rigid3::Identity());
  EXPECT_EQ(sensor.Render(0, RenderMode::kFull).depth,
            RenderWall(1.5, SurfaceMaterial{0.6, 0.0}, StructuredLight()).depth);
  try {
    SurfaceMaterial bad;
    bad.subsurface_mm = 3.5;
    bad.Validate("scene.materials.skin");
    FAIL() << "accepted a negative spread";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scene.materials.skin.subsurface_mm"));
  }
}

TEST(StructuredLight, ErrorsAreSpatiallyCorrelatedUnlikeTheStatisticalModel) {
  // Residual correlation of horizontal neighbours on a wall at 2 m: block matching shares most
  // of the window between neighbours (correlated), per-pixel noise does not.
  auto neighbour_correlation = [](const RgbdFrame& frame, double z) {
    const int w = frame.depth_intrinsics.width;
    double sxy = 0, sxx = 0;
    for (int v = 90; v < 390; ++v) {
      for (int u = 120; u < 520; ++u) {
        const uint16_t a = frame.depth[v * w + u], b = frame.depth[v * w + u + 1];
        if (a == 0 || b == 0) continue;
        const double ea = a * frame.depth_scale - z, eb = b * frame.depth_scale - z;
        sxy += ea * eb;
        sxx += 0.5 * (ea * ea + eb * eb);
      }
    }
    return sxy / sxx;
  };
  const double structured =
      neighbour_correlation(RenderWall(2.0, SurfaceMaterial{0.7, 0.0}, StructuredLight()), 2.0);
  const double statistical =
      neighbour_correlation(RenderWall(2.0, SurfaceMaterial{0.7, 0.0}, Statistical()), 2.0);
  // 0.41 with the Gaussian sub-pixel fit (0.5-0.6 with the parabola, whose pixel-locking bias
  // is common to the whole fronto-parallel wall); real frames: 0.41-0.47 at lag 1 on planar
  // patches (mmh sensor-check).
  EXPECT_GT(structured, 0.3);
  EXPECT_LT(statistical, 0.2);
}

TEST(StructuredLight, SubPixelDisparitiesAreNotLockedToWholePixels) {
  // A wall turned 40 deg about the vertical at 1.5 m sweeps the disparity's fraction across the
  // image. A real Kinect frame's raw values fill the eight 1/8-px bins alike (the TUM frame of
  // mmh sensor-check: shares 0.121-0.132); a parabola through the correlation scores crowds
  // them towards whole pixels (0.08-0.17 on rendered frames before the Gaussian fit).
  RayScene scene;
  const Rigid3 facing = WallAt(1.5);
  const uint32_t wall = scene.AddStatic(
      "wall", Quad(20, 20),
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())) *
                 facing.rotation,
             facing.translation));
  scene.SetMaterial(wall, SurfaceMaterial{0.7, 0.0});
  scene.Commit();
  KinectSensor sensor(StructuredLight(), &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0, RenderMode::kFull);
  const KinectCalibration calibration;
  std::vector<int> bins(8, 0);
  int valid = 0;
  for (const uint16_t d : frame.depth) {
    if (d == 0) continue;
    ++bins[RawFromDepth(d * frame.depth_scale, calibration) % 8];
    ++valid;
  }
  ASSERT_GT(valid, 100000);
  for (int b = 0; b < 8; ++b) {
    EXPECT_NEAR(static_cast<double>(bins[b]) / valid, 0.125, 0.02) << "bin " << b;
  }
}

// A 20 cm board at 1 m in front of a wall at 2 m, both of IR albedo 0.7.
void AddBoardBeforeWall(RayScene& scene) {
  const uint32_t wall = scene.AddStatic("wall", Quad(20, 20), WallAt(2.0));
  const uint32_t board = scene.AddStatic("board", Quad(0.2, 0.2), WallAt(1.0));
  scene.SetMaterial(wall, SurfaceMaterial{0.7, 0.0});
  scene.SetMaterial(board, SurfaceMaterial{0.7, 0.0});
  scene.Commit();
}

// The scene of AddBoardBeforeWall rendered whole with `options`, the missing causes kept, and the
// board's first and last columns in the delivered image (half-width 0.1 m at 1 m).
struct BoardFrame {
  RgbdFrame frame;
  std::vector<MissingCause> causes;
  int left_edge = 0, right_edge = 0;
};
BoardFrame RenderBoard(const RayScene& scene, const KinectSensorOptions& options) {
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  sensor.KeepMissingCauses(true);
  BoardFrame b;
  b.frame = sensor.Render(0, RenderMode::kFull);
  b.causes.assign(sensor.missing_causes().begin(), sensor.missing_causes().end());
  const PinholeIntrinsics& k = b.frame.depth_intrinsics;
  b.left_edge = static_cast<int>(std::ceil(k.cx - k.fx * 0.1 / 1.0));
  b.right_edge = static_cast<int>(std::floor(k.cx + k.fx * 0.1 / 1.0));
  return b;
}

TEST(StructuredLight, ShadowOfANearBoxFallsOnTheProjectorSideAndIsMissing) {
  // A 20 cm board at 1 m in front of a wall at 2 m: the projector (at +x) cannot light a band
  // left of the board of width f_x s (1/z_near - 1/z_far) (s = 5 cm from the colour camera).
  // Matched on the colour camera's grid (the shortcut, match_on_ir_grid false), whose shadow and
  // gap are the geometry's alone; on the IR grid (the default) the registration moves the gap:
  // MatchedOnTheIrGridTheIrCamerasGapComesFromTheRegistration. With windows centred in the shadow
  // rejected outright (match_in_shadow false; with it, the default since 2026-12-01, the
  // correlation decides: MatchingInTheShadowKeepsTheWallBesideItsEdge).
  RayScene scene;
  AddBoardBeforeWall(scene);
  KinectSensorOptions options = StructuredLight();
  options.structured_light.match_on_ir_grid = false;
  options.structured_light.match_in_shadow = false;
  const auto [frame, causes, left_edge, right_edge] = RenderBoard(scene, options);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const int v = 240;
  const double shadow = k.fx * 0.05 * (1.0 / 1.0 - 1.0 / 2.0);  // about 13 px
  int missing_left = 0, shadow_cause = 0;
  for (int u = left_edge - static_cast<int>(shadow) + 2; u < left_edge - 2; ++u) {
    missing_left += frame.depth[v * k.width + u] == 0;
    shadow_cause += causes[v * k.width + u] == MissingCause::kShadow;
  }
  EXPECT_EQ(missing_left, static_cast<int>(shadow) - 4);
  EXPECT_EQ(shadow_cause, static_cast<int>(shadow) - 4);
  // Right of the board (the IR camera's side) no shadow: the wall is measured a few pixels
  // beyond the edge.
  int valid_right = 0;
  for (int u = right_edge + 8; u < right_edge + 20; ++u)
    valid_right += frame.depth[v * k.width + u] != 0;
  EXPECT_GE(valid_right, 10);
}

TEST(StructuredLight, MatchingInTheShadowKeepsTheWallBesideItsEdge) {
  // The board and wall of AddBoardBeforeWall. With match_in_shadow a window centred in the shadow
  // is judged by its correlation: near the shadow's far end its lit part (the wall) still matches
  // and gives the wall's depth, near the board the board's; deep in the shadow the window is dark
  // (low signal), never "shadow". On the colour camera's grid (match_on_ir_grid false), as
  // ShadowOfANearBoxFallsOnTheProjectorSideAndIsMissing.
  RayScene scene;
  AddBoardBeforeWall(scene);
  auto missing_left = [&](bool match_in_shadow, std::vector<MissingCause>* causes) {
    KinectSensorOptions options = StructuredLight();
    options.structured_light.match_on_ir_grid = false;
    options.structured_light.match_in_shadow = match_in_shadow;
    const BoardFrame b = RenderBoard(scene, options);
    const RgbdFrame& frame = b.frame;
    const PinholeIntrinsics& k = frame.depth_intrinsics;
    const int left_edge = b.left_edge;
    int missing = 0, valid = 0, on_a_surface = 0;
    for (int v = 200; v < 280; ++v) {
      for (int u = left_edge - 30; u < left_edge; ++u) {
        const size_t p = static_cast<size_t>(v) * k.width + u;
        missing += frame.depth[p] == 0;
        // A window whose lit part is the wall gives the wall's depth, one whose lit part is the
        // board the board's (edge fattening into the shadow); a few match neither (a half-dark
        // window's spurious peak: flying pixels).
        const double z = frame.depth[p] * frame.depth_scale;
        if (z != 0) {
          ++valid;
          on_a_surface += std::min(std::abs(z - 2.0), std::abs(z - 1.0)) < 0.06;
        }
        if (causes != nullptr) causes->push_back(b.causes[p]);
      }
    }
    EXPECT_GT(on_a_surface, 0.95 * valid) << on_a_surface << " of " << valid;
    return missing;
  };
  std::vector<MissingCause> causes;
  const int rejected = missing_left(false, nullptr);
  const int matched = missing_left(true, &causes);
  // About 13 px of shadow over 80 rows; measured 1122 and 1013 missing of 2400.
  EXPECT_LT(matched, rejected - 40) << rejected << " " << matched;
  EXPECT_GT(matched, rejected / 2) << rejected << " " << matched;
  EXPECT_EQ(std::count(causes.begin(), causes.end(), MissingCause::kShadow), 0);
}

TEST(StructuredLight, MatchedOnTheIrGridTheIrCamerasGapComesFromTheRegistration) {
  // The board and wall of AddBoardBeforeWall, matched on the IR camera's grid (580 px, 2.5 cm to
  // -x) and registered to the colour camera's (525 px). Right of the board the colour camera sees
  // wall the IR camera did not: a gap of f 0.025 (1 / 1 - 1 / 2) = 6.6 px, missing as "shadow"
  // (hidden from the IR camera). Left of it the projector's shadow, 21.8 IR pixels wide, less
  // the 6.6 px the board moves over it: 13.1 px, as the projector's 5 cm from the colour camera
  // gives.
  RayScene scene;
  AddBoardBeforeWall(scene);
  KinectSensorOptions options = StructuredLight();
  options.structured_light.match_on_ir_grid = true;
  const auto [frame, causes, left_edge, right_edge] = RenderBoard(scene, options);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  EXPECT_EQ(k.fx, options.intrinsics.fx);
  EXPECT_TRUE(frame.color_T_depth.translation.isZero());
  ASSERT_EQ(causes.size(), frame.depth.size());
  int gap = 0, gap_shadow = 0, wall_right = 0, shadow_left = 0, on_surface = 0, valid = 0;
  for (int v = 200; v < 280; ++v) {
    const size_t row = static_cast<size_t>(v) * k.width;
    // (The board's outline bleeds a pixel or two into the gap: from its third pixel on.)
    for (int u = right_edge + 3; u <= right_edge + 5; ++u) {
      gap += frame.depth[row + u] == 0;
      gap_shadow += causes[row + u] == MissingCause::kShadow;
    }
    for (int u = right_edge + 12; u < right_edge + 20; ++u) wall_right += frame.depth[row + u] != 0;
    for (int u = left_edge - 11; u < left_edge - 3; ++u) shadow_left += frame.depth[row + u] == 0;
    for (int u = left_edge - 40; u < right_edge + 40; ++u) {
      const double z = frame.depth[row + u] * frame.depth_scale;
      if (z == 0) continue;
      ++valid;
      on_surface += std::min(std::abs(z - 1.0), std::abs(z - 2.0)) < 0.03;
    }
  }
  EXPECT_GE(gap, 3 * 80 * 95 / 100);
  EXPECT_EQ(gap_shadow, gap);
  EXPECT_GE(wall_right, 8 * 80 * 95 / 100);
  EXPECT_GE(shadow_left, 8 * 80 * 95 / 100);
  EXPECT_GE(on_surface, valid * 99 / 100) << on_surface << " of " << valid;
  // Same bytes for any thread count.
  auto render = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    KinectSensor other(options, &scene, Rigid3::Identity());
    return other.Render(2, RenderMode::kFull).depth;
  };
  EXPECT_EQ(render(1), render(2));
}

// A wall turned 34 degrees about the vertical, so that the depth steps from lattice value to
// lattice value along every row. Between IR pixels one lattice step apart the registered
// footprints part by f_colour t / (8 f_ir b) = 0.038 colour pixels, and a colour pixel whose
// centre falls in that gap gets no depth: isolated pinholes (a missing pixel whose four
// neighbours have depth) along the lattice's iso-depth lines (measured: 118 in the 300 x 200 px
// centre). The default footprint growth (structured_light.registration_growth_px, 0.05 px)
// closes them (measured: 2 left); a growth over 1 px is refused.
TEST(StructuredLight, TheRegistrationsFootprintGrowthClosesTheLatticePinholes) {
  RayScene scene;
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(-0.6, Eigen::Vector3d::UnitY()));
  const uint32_t wall =
      scene.AddStatic("wall", Quad(20, 20), Rigid3(turn, Eigen::Vector3d::Zero()) * WallAt(1.5));
  scene.SetMaterial(wall, SurfaceMaterial{0.7, 0.0});
  scene.Commit();
  auto pinholes = [&](double growth) {
    KinectSensorOptions options = StructuredLight();
    options.structured_light.match_on_ir_grid = true;
    options.structured_light.registration_growth_px = growth;
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    const RgbdFrame frame = sensor.Render(0, RenderMode::kFull);
    const int w = frame.depth_intrinsics.width;
    int count = 0;
    for (int v = 140; v < 340; ++v) {
      for (int u = 170; u < 470; ++u) {
        const size_t i = static_cast<size_t>(v) * w + u;
        count += frame.depth[i] == 0 && frame.depth[i - 1] != 0 && frame.depth[i + 1] != 0 &&
                 frame.depth[i - w] != 0 && frame.depth[i + w] != 0;
      }
    }
    return count;
  };
  const int exact = pinholes(0.0),
            grown = pinholes(StructuredLightOptions().registration_growth_px);
  std::printf("pinholes in 300 x 200 px: %d with exact footprints, %d grown by 0.05 px\n", exact,
              grown);
  EXPECT_GT(exact, 40);
  EXPECT_LT(grown, exact / 10);
  KinectSensorOptions bad = StructuredLight();
  bad.structured_light.registration_growth_px = 2.0;
  EXPECT_THAT(ErrorOf([&] { KinectSensor sensor(bad, &scene, Rigid3::Identity()); }),
              HasSubstr("sensor.structured_light.registration_growth_px"));
}

TEST(StructuredLight, FramesAreIndependentOfTheThreadCountAndFollowTheSeed) {
  auto render = [](int threads, uint64_t seed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    KinectSensorOptions options = StructuredLight();
    options.seed = seed;
    return RenderWall(1.7, SurfaceMaterial{0.4, 0.1}, options, 3);
  };
  const RgbdFrame one = render(1, 5), two = render(2, 5), other = render(2, 6);
  EXPECT_EQ(one.depth, two.depth);
  EXPECT_EQ(one.rgb, two.rgb);
  EXPECT_NE(one.depth, other.depth);
  // The slanted windows' second pass, on a slanted wall (its sums are exact integers).
  for (const SlantedWindows slanted : {SlantedWindows::kFirstOrder, SlantedWindows::kSheared}) {
    auto slanted_wall = [slanted](int threads) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      RayScene scene;
      const Eigen::Quaterniond turn(Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitX()));
      scene.AddStatic("wall", Quad(4, 4),
                      Rigid3(turn * WallAt(0.0).rotation, Eigen::Vector3d(0, 0, 0.9)));
      scene.Commit();
      KinectSensorOptions options = StructuredLight();
      options.structured_light.slanted_windows = slanted;
      KinectSensor sensor(options, &scene, Rigid3::Identity());
      return sensor.Render(0, RenderMode::kFull).depth;
    };
    const std::vector<uint16_t> one_thread = slanted_wall(1);
    EXPECT_EQ(one_thread, slanted_wall(2));
    EXPECT_GT(std::count_if(one_thread.begin(), one_thread.end(), [](uint16_t d) { return d > 0; }),
              100000);
  }
}

TEST(StructuredLight, NonsenseOptionsAreRejectedNamingTheField) {
  RayScene scene;
  scene.AddStatic("wall", Quad(20, 20), WallAt(2.0));
  scene.Commit();
  KinectSensorOptions options = StructuredLight();
  options.structured_light.window_px = 8;
  try {
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor.structured_light.window_px"));
    EXPECT_THAT(e.what(), HasSubstr("8"));
  }
  SurfaceMaterial bad{1.5, 0.0};
  EXPECT_THROW(bad.Validate("scene.materials.table"), InputError);
  StructuredLightOptions unrefined;
  unrefined.parabola_subpixel = false;
  unrefined.slanted_windows = SlantedWindows::kFirstOrder;
  EXPECT_THAT(ErrorOf([&] { unrefined.Validate("sensor.structured_light"); }),
              HasSubstr("sensor.structured_light.slanted_windows"));
  for (const auto& [density, brightness, field] :
       {std::tuple{-0.1, 0.2, "faint_dot_density"}, std::tuple{0.5, 0.0, "faint_dot_brightness"},
        std::tuple{0.5, 1.5, "faint_dot_brightness"}}) {
    StructuredLightOptions faint;
    faint.faint_dot_density = density;
    faint.faint_dot_brightness = brightness;
    try {
      faint.Validate("sensor.structured_light");
      FAIL() << field << " accepted";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(std::string("sensor.structured_light.") + field));
    }
  }
}

TEST(StructuredLight, FaintDotsBetweenTheBrightOnesQuietenSlantedSurfaces) {
  // On a slanted surface the disparity changes across the window, and a match strays from the
  // window's centre towards where its dots are: about 1 / sqrt(12 rho) px for rho dots per pixel,
  // times the gradient (docs/sensor.md, "Small patches like for like"). A faint, dense second
  // population of dots pulls the match back towards the centre. A wall at 0.75 m turned 50 deg,
  // the small-patch noise over the per-pixel model in the image's centre (measured 0.84 without,
  // 0.72 with 0.6 faint dots per pixel of 0.35 the brightness; facing the camera 0.52 without).
  auto noise_over_model = [](double faint_density) {
    KinectSensorOptions options = StructuredLight();
    options.structured_light.faint_dot_density = faint_density;
    options.structured_light.faint_dot_brightness = 0.35;
    return CentreNoiseOverModel(RenderTurnedWall(50, options), options);
  };
  const double bright_only = noise_over_model(0.0);
  const double with_faint = noise_over_model(0.6);
  EXPECT_LT(with_faint, bright_only - 0.05) << bright_only << " " << with_faint;
}

TEST(StructuredLight, SlantedWindowsTakeTheSlopesExcessNoiseAway) {
  // A window matched as one disparity on a slanted surface strays from the centre's disparity by
  // g . c (c: the centroid of the pattern's detail under the window), a fixed error per pixel that
  // grows with the slope; the real Xtion's small-patch noise does not grow with incidence
  // (docs/sensor.md, "Slanted windows"). Walls at 0.75 m, facing the camera and turned 50 deg:
  // the small-patch noise over the per-pixel model in the image's centre per mode, and the rms
  // depth difference of each mode from the exact sheared match.
  struct Result {
    double noise_over_model = 0;
    std::vector<uint16_t> depth;
  };
  auto render = [](double turn_deg, SlantedWindows slanted) {
    KinectSensorOptions options = StructuredLight();
    options.structured_light.slanted_windows = slanted;
    const RgbdFrame frame = RenderTurnedWall(turn_deg, options);
    Result result;
    for (int v = 140; v < 340; ++v) {
      for (int u = 200; u < 440; ++u) {
        result.depth.push_back(
            frame.depth[static_cast<size_t>(v) * frame.depth_intrinsics.width + u]);
      }
    }
    result.noise_over_model = CentreNoiseOverModel(frame, options);
    return result;
  };
  auto rms_difference = [](const Result& a, const Result& b) {
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < a.depth.size(); ++i) {
      if (a.depth[i] == 0 || b.depth[i] == 0) continue;
      const double d = (static_cast<double>(a.depth[i]) - b.depth[i]) * 0.0002;  // 0.2 mm units
      sum += d * d;
      ++n;
    }
    return n > 0 ? std::sqrt(sum / n) : 0.0;
  };
  for (const double turn_deg : {0.0, 50.0}) {
    const Result off = render(turn_deg, SlantedWindows::kOff);
    const Result first_order = render(turn_deg, SlantedWindows::kFirstOrder);
    const Result sheared = render(turn_deg, SlantedWindows::kSheared);
    const double off_to_sheared = rms_difference(off, sheared);
    const double first_order_to_sheared = rms_difference(first_order, sheared);
    std::printf(
        "wall turned %.0f deg: noise / model off %.3f, first order %.3f, sheared %.3f; rms "
        "depth difference from sheared: off %.2f mm, first order %.2f mm\n",
        turn_deg, off.noise_over_model, first_order.noise_over_model, sheared.noise_over_model,
        1e3 * off_to_sheared, 1e3 * first_order_to_sheared);
    SCOPED_TRACE(testing::Message() << "turned " << turn_deg << " deg");
    if (turn_deg == 0.0) {
      // Facing the camera the gradient is about 0: every mode the same to within the lattice.
      EXPECT_NEAR(first_order.noise_over_model, off.noise_over_model, 0.05);
      EXPECT_NEAR(sheared.noise_over_model, off.noise_over_model, 0.05);
    } else {
      // Turned, most of the slope's excess goes (measured: 0.84 plain, 0.61 first order, 0.57
      // sheared, facing 0.52), and the first-order correction takes most of the sheared match's
      // gain (86 %; its depths 1.1 mm rms from the sheared's, the plain match's 1.9 mm: at 0.75 m
      // the lattice's step is 1.6 mm, so these are mostly single steps).
      EXPECT_LT(sheared.noise_over_model, off.noise_over_model - 0.2);
      EXPECT_GT(off.noise_over_model - first_order.noise_over_model,
                0.75 * (off.noise_over_model - sheared.noise_over_model));
      EXPECT_LT(first_order_to_sheared, 0.7 * off_to_sheared);
    }
  }
}

TEST(StructuredLight, SlantedWallsKeepTheirSlope) {
  // Faces seen obliquely (the proxy's broad face from the camera above: a disparity gradient down
  // the window) must not be tilted by the block matcher: a window matched as one disparity takes
  // the gradient's mean at its centre. A plane fitted to the matched depth in the image's centre
  // (140 x 140 px, a wall at 0.85 m turned about x and then y) against the true plane: slope
  // errors 0.00-0.02 deg on either grid (the statistical model's 0.00; with first-order slanted
  // windows the same), so the tracker's face-on
  // errors on the Soldier's 3-4 cm faces (docs/tracker.md, "Face-on frames") are not a bias of
  // slanted surfaces as such.
  for (const auto& [about_x_deg, about_y_deg] :
       {std::pair{-50.0, 0.0}, std::pair{50.0, 40.0}, std::pair{-30.0, 40.0}}) {
    RayScene scene;
    const Eigen::Quaterniond turn(
        Eigen::AngleAxisd(about_y_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
        Eigen::AngleAxisd(about_x_deg * M_PI / 180, Eigen::Vector3d::UnitX()));
    const Rigid3 wall_pose(turn * WallAt(0.0).rotation, Eigen::Vector3d(0, 0, 0.85));
    const uint32_t wall = scene.AddStatic("wall", Quad(4, 4), wall_pose);
    scene.SetMaterial(wall, SurfaceMaterial{0.6, 0.0});
    scene.Commit();
    const Eigen::Vector3d normal = wall_pose.rotation * Eigen::Vector3d::UnitZ();
    for (const SlantedWindows slanted : {SlantedWindows::kOff, SlantedWindows::kFirstOrder}) {
      KinectSensorOptions options = StructuredLight();
      options.structured_light.slanted_windows = slanted;
      KinectSensor sensor(options, &scene, Rigid3::Identity());
      const RgbdFrame frame = sensor.Render(0, RenderMode::kFull);
      const PinholeIntrinsics& in = frame.depth_intrinsics;
      // Least squares z = a x + b y + c over the back-projected points, and the depth bias along
      // each pixel's ray.
      Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
      Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
      double error_sum = 0;
      int count = 0;
      for (int v = 170; v < 310; ++v) {
        for (int u = 250; u < 390; ++u) {
          const uint16_t d = frame.depth[v * in.width + u];
          if (d == 0) continue;
          const Eigen::Vector3d p = in.BackProject(u, v, d * frame.depth_scale);
          const Eigen::Vector3d row(p.x(), p.y(), 1.0);
          normal_matrix += row * row.transpose();
          rhs += row * p.z();
          const Eigen::Vector3d ray = in.BackProject(u, v, 1.0);
          error_sum += d * frame.depth_scale - normal.dot(wall_pose.translation) / normal.dot(ray);
          ++count;
        }
      }
      ASSERT_GT(count, 0.9 * 140 * 140);
      const Eigen::Vector3d abc = normal_matrix.ldlt().solve(rhs);
      const double slope_x_deg =
          (std::atan(abc(0)) - std::atan(-normal.x() / normal.z())) * 180 / M_PI;
      const double slope_y_deg =
          (std::atan(abc(1)) - std::atan(-normal.y() / normal.z())) * 180 / M_PI;
      SCOPED_TRACE(testing::Message() << about_x_deg << " deg about x, " << about_y_deg
                                      << " about y, slanted windows " << static_cast<int>(slanted));
      EXPECT_LT(std::abs(slope_x_deg), 0.1);
      EXPECT_LT(std::abs(slope_y_deg), 0.1);
      // Within a quarter of the lattice step at 0.85 m (2.1 mm).
      EXPECT_LT(std::abs(error_sum / count), 0.0005);
    }
  }
}

}  // namespace
}  // namespace mmh::sim
