// The synthetic Kinect's statistical mode against analytic geometry and its own noise model, with
// p-values (structured light, the default mode: structured_light_test.cc).
#include "sim/kinect_sensor.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <tuple>

#include "core/error.h"
#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "tests/sim/sensor_modes.h"
#include "tests/test_meshes.h"

namespace mmh::sim {
namespace {

using ::testing::HasSubstr;

using test_util::Quad;

// An axis-aligned box centred at the origin.
TriangleMesh Box(double sx, double sy, double sz) {
  return test_util::CentredBox(sx, sy, sz, {60, 60, 60});
}

// Camera at the world origin looking along +z (world = camera frame).
Rigid3 FacingCamera(double z, const Eigen::Vector3d& normal = Eigen::Vector3d::UnitZ()) {
  // A quad's +z normal turned to face the camera (-z) or the given normal.
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), normal);
  return Rigid3(q, Eigen::Vector3d(0, 0, z));
}

using test_modes::Statistical;

KinectSensorOptions Exact() {
  KinectSensorOptions options = Statistical();
  options.noise = false;
  options.quantise = false;
  return options;
}

TEST(KinectSensor, FrontoParallelPlaneHasTheExactDepth) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.25, -Eigen::Vector3d::UnitZ()));
  scene.Commit();
  KinectSensor sensor(Exact(), &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  ASSERT_EQ(frame.depth.size(), 640u * 480u);
  for (uint16_t d : frame.depth) ASSERT_EQ(d, 6250);  // 1.25 m * 5000
}

TEST(KinectSensor, TiltedPlaneMatchesRayPlaneIntersectionAndBackProjects) {
  // Plane through (0, 0, 1.5) with normal n (tilted 35 degrees about a skew axis): the depth of
  // pixel (u, v) is n.p0 / n.r with r = ((u - cx) / fx, (v - cy) / fy, 1).
  const Eigen::Vector3d n = Eigen::Vector3d(0.4, -0.3, -1.0).normalized();
  RayScene scene;
  scene.AddStatic("wall", Quad(20, 20), FacingCamera(1.5, n));
  scene.Commit();
  KinectSensor sensor(Exact(), &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const double c = n.dot(Eigen::Vector3d(0, 0, 1.5));
  int checked = 0;
  for (int v = 0; v < k.height; v += 7) {
    for (int u = 0; u < k.width; u += 5) {
      const uint16_t d = frame.depth[v * k.width + u];
      if (d == 0) continue;  // IR shadow / range: not tested here
      const Eigen::Vector3d r((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const double z = c / n.dot(r);
      ASSERT_NEAR(d * frame.depth_scale, z, 0.6 * frame.depth_scale) << u << "," << v;
      // Back-projection lies on the plane within the depth unit (moved along the ray).
      const Eigen::Vector3d p = k.BackProject(u, v, d * frame.depth_scale);
      ASSERT_NEAR(n.dot(p), c, 0.6 * frame.depth_scale * std::abs(n.dot(r)));
      ++checked;
    }
  }
  EXPECT_GT(checked, 5000);
}

TEST(KinectSensor, BoxFrontFaceAndSilhouetteAreExact) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(2.0, -Eigen::Vector3d::UnitZ()));
  const uint32_t box = scene.AddMoving("box", Box(0.2, 0.1, 0.1));
  scene.SetPose(box, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05, -0.02, 1.0)));
  scene.Commit();
  KinectSensorOptions options = Exact();
  options.missing.projector_shadow = false;
  options.missing.ir_camera_occlusion = false;
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  // Front face at z = 0.95 spans x in [-0.05, 0.15], y in [-0.07, 0.03].
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double x = (u - k.cx) / k.fx;
      const double y = (v - k.cy) / k.fy;
      const double margin = 1.0 / k.fx;  // one pixel at the silhouette is not decided here
      const bool inside = x * 0.95 > -0.05 + margin && x * 0.95 < 0.15 - margin &&
                          y * 0.95 > -0.07 + margin && y * 0.95 < 0.03 - margin;
      // The ray misses the box when it passes the front face's outline already at its depth
      // (the nearest point of the box on that side).
      const bool outside_box = x * 0.95 < -0.05 - 2 * margin || x * 0.95 > 0.15 + 2 * margin ||
                               y * 0.95 < -0.07 - 2 * margin || y * 0.95 > 0.03 + 2 * margin;
      const uint16_t d = frame.depth[v * k.width + u];
      if (inside) {
        ASSERT_EQ(d, 4750) << u << "," << v;
      }
      if (outside_box) {
        ASSERT_EQ(d, 10000) << u << "," << v;
      }
    }
  }
}

// sRGB of Lambertian shading, independently of the renderer's tables (IEC 61966-2-1).
int ShadedSrgb(int albedo, const Eigen::Vector3d& normal, const ColorModel& model) {
  const double c = albedo / 255.0;
  const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  const Eigen::Vector3d light =
      Eigen::Vector3d(model.light_x, model.light_y, model.light_z).normalized();
  const double lit =
      std::min(1.0, linear * (model.ambient + model.diffuse * std::max(0.0, normal.dot(light))));
  const double encoded = lit <= 0.0031308 ? 12.92 * lit : 1.055 * std::pow(lit, 1 / 2.4) - 0.055;
  return static_cast<int>(std::lround(255 * encoded));
}

TEST(KinectSensor, ColourIsTheLambertianShadingOfStaticAndMovingFaces) {
  // A wall facing the camera and a turned box in front of it: the box's front face normal is the
  // box's rotation applied to -z. Colour without noise must be their shading within one level
  // (the renderer encodes through a 4096-step table).
  RayScene scene;
  TriangleMesh wall = Quad(10, 10);
  wall.face_colors.rowwise() = Eigen::Matrix<uint8_t, 1, 3>(200, 120, 90);
  scene.AddStatic("wall", wall, FacingCamera(1.5, -Eigen::Vector3d::UnitZ()));
  TriangleMesh box = Box(0.2, 0.2, 0.05);
  box.face_colors.rowwise() = Eigen::Matrix<uint8_t, 1, 3>(40, 160, 220);
  const uint32_t a = scene.AddMoving("box", box);
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 0).normalized()));
  scene.SetPose(a, Rigid3(turn, Eigen::Vector3d(0, 0, 1.0)));
  scene.Commit();
  KinectSensorOptions options = Exact();
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  const int centre = 3 * (240 * 640 + 320);
  const int corner = 3 * (20 * 640 + 20);
  const Eigen::Vector3d box_normal = turn * -Eigen::Vector3d::UnitZ();
  const int box_albedo[3] = {40, 160, 220};
  const int wall_albedo[3] = {200, 120, 90};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(frame.rgb[centre + c], ShadedSrgb(box_albedo[c], box_normal, options.color), 1)
        << "box channel " << c;
    EXPECT_NEAR(frame.rgb[corner + c],
                ShadedSrgb(wall_albedo[c], -Eigen::Vector3d::UnitZ(), options.color), 1)
        << "wall channel " << c;
  }
}

TEST(KinectSensor, EveryDepthLiesOnTheDisparityLattice) {
  RayScene scene;
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, 0.5, -1.0).normalized();
  scene.AddStatic("wall", Quad(20, 20), FacingCamera(1.8, n));
  scene.Commit();
  KinectSensorOptions options = Statistical();  // full noise
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(3);
  const double lattice = options.calibration.lattice_constant();
  int valid = 0;
  for (uint16_t d : frame.depth) {
    if (d == 0) continue;
    ++valid;
    const double z = d * frame.depth_scale;
    const double raw = options.calibration.raw_offset - lattice / z;
    // The depth unit (0.2 mm) moves raw by at most lattice / z^2 * 0.1 mm.
    const double tolerance = lattice / (z * z) * 0.5 * frame.depth_scale + 1e-6;
    ASSERT_NEAR(raw, std::round(raw), tolerance) << "depth " << z;
  }
  EXPECT_GT(valid, 200000);
}

// Two-sided p-value of a sample variance against sigma^2 (chi-squared with n - 1 df).
double VarianceP(double sum_sq_dev, double n, double sigma2) {
  boost::math::chi_squared chi(n - 1);
  const double x = sum_sq_dev / sigma2;
  const double lower = boost::math::cdf(chi, x);
  return 2 * std::min(lower, 1 - lower);
}

TEST(KinectSensor, FrontoParallelNoiseHasTheModelledSigmaAt06To3m) {
  for (double z : {0.6, 1.0, 1.5, 2.2, 3.0}) {
    RayScene scene;
    scene.AddStatic("wall", Quad(30, 30), FacingCamera(z, -Eigen::Vector3d::UnitZ()));
    scene.Commit();
    KinectSensorOptions options = Statistical();
    options.quantise = false;  // sigma_z alone; the lattice is tested separately
    options.seed = 11;
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    const RgbdFrame frame = sensor.Render(0);
    std::vector<double> values;
    for (uint16_t d : frame.depth) {
      if (d != 0) values.push_back(d * frame.depth_scale);
    }
    ASSERT_GT(values.size(), 250000u);
    const double n = values.size();
    const double mean = std::accumulate(values.begin(), values.end(), 0.0) / n;
    double ss = 0;
    for (double x : values) ss += (x - mean) * (x - mean);
    // Rounding to the 0.2 mm depth unit adds its uniform variance.
    const double sigma = options.axial.Sigma(z, 0.0);
    const double sigma2 = sigma * sigma + frame.depth_scale * frame.depth_scale / 12;
    const double p_var = VarianceP(ss, n, sigma2);
    const double t = (mean - z) / std::sqrt(sigma2 / n);
    const double p_mean = 2 * boost::math::cdf(boost::math::normal(), -std::abs(t));
    EXPECT_GT(p_var, 1e-3) << "z " << z << " sd " << std::sqrt(ss / n) << " model " << sigma;
    EXPECT_GT(p_mean, 1e-3) << "z " << z << " mean " << mean;
  }
}

TEST(KinectSensor, ShadowBesideNearEdgesOnTheProjectorSide) {
  // A box 1 m away in front of a wall at 1.5 m. Registered depth: the projector sits 5 cm to the
  // +x side of the colour camera, so the wall is shadowed for fx * 0.05 * (1/1 - 1/1.5) = 8.75 px
  // left of the box; the IR camera (2.5 cm to -x) misses 4.4 px right of it.
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.5, -Eigen::Vector3d::UnitZ()));
  const uint32_t box = scene.AddMoving("box", Box(0.2, 0.2, 0.02));
  scene.SetPose(box, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.01)));
  scene.Commit();
  KinectSensor sensor(Exact(), &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const int v = 240;
  const double left_edge = k.cx - 0.1 * k.fx;   // u of x = -0.1 at z = 1
  const double right_edge = k.cx + 0.1 * k.fx;  // u of x = +0.1
  const double shadow = k.fx * 0.05 * (1.0 - 1.0 / 1.5);
  const double ir = k.fx * 0.025 * (1.0 - 1.0 / 1.5);
  for (int u = 0; u < k.width; ++u) {
    const uint16_t d = frame.depth[v * k.width + u];
    if (u < left_edge - shadow - 1 || (u > right_edge + ir + 1)) {
      EXPECT_EQ(d, 7500) << u;
    }
    if (u > left_edge - shadow + 1 && u < left_edge - 1) {
      EXPECT_EQ(d, 0) << "shadow " << u;
    }
    if (u > right_edge + 1 && u < right_edge + ir - 1) {
      EXPECT_EQ(d, 0) << "IR occlusion " << u;
    }
    if (u > left_edge + 1 && u < right_edge - 1) {
      EXPECT_EQ(d, 5000) << u;
    }
  }
}

TEST(KinectSensor, NoisyMissingPixelsConcentrateBesideEdgesOnTheProjectorSide) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.5, -Eigen::Vector3d::UnitZ()));
  const uint32_t box = scene.AddMoving("box", Box(0.3, 0.3, 0.02));
  scene.SetPose(box, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1.01)));
  scene.Commit();
  KinectSensorOptions options = Statistical();
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(5);
  const PinholeIntrinsics& k = frame.depth_intrinsics;
  const int left_edge = static_cast<int>(k.cx - 0.15 * k.fx);
  const int right_edge = static_cast<int>(k.cx + 0.15 * k.fx);
  // Bands of 6 px beside the left (projector-shadow) side and far from both edges.
  long shadow_missing = 0, shadow_n = 0, far_missing = 0, far_n = 0;
  for (int v = static_cast<int>(k.cy - 0.1 * k.fy); v < k.cy + 0.1 * k.fy; ++v) {
    for (int u = left_edge - 7; u < left_edge - 1; ++u) {
      shadow_missing += frame.depth[v * k.width + u] == 0;
      ++shadow_n;
    }
    for (int u = 10; u < left_edge - 40; ++u) {
      far_missing += frame.depth[v * k.width + u] == 0;
      ++far_n;
    }
  }
  const double far_rate = static_cast<double>(far_missing) / far_n;
  EXPECT_LT(far_rate, 0.01);
  // One-sided binomial test: P(X >= shadow_missing | rate = 10 * far rate + 0.01).
  const double p0 = std::min(0.5, 10 * far_rate + 0.01);
  const double p = boost::math::cdf(
      boost::math::complement(boost::math::binomial(shadow_n, p0), shadow_missing - 1));
  EXPECT_LT(p, 1e-6) << shadow_missing << " of " << shadow_n;
  (void)right_edge;
}

// Incremental frames re-scan the occlusion only in windows around what changed (see
// OccludeWindows); full re-renders scan every row whole. Both kernels, both depth geometries (the
// registered one has two occluder sources, the IR camera's own image one).
TEST(KinectSensor, IncrementalFramesEqualFullRerenders) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.6, -Eigen::Vector3d::UnitZ()));
  scene.AddStatic("floor", Quad(3, 3),
                  Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitX())),
                         Eigen::Vector3d(0, 0.3, 1.2)));
  const uint32_t a = scene.AddMoving("a", Box(0.1, 0.05, 0.08));
  const uint32_t b = scene.AddMoving("b", Box(0.04, 0.04, 0.04));
  scene.Commit();
  for (const bool registered : {true, false}) {
    for (const bool vector_kernels : {true, false}) {
      SCOPED_TRACE(testing::Message() << "registered " << registered << ", vector kernels "
                                      << KinectSensor::SetVectorKernels(vector_kernels));
      KinectSensorOptions options = Statistical();
      options.registered = registered;
      KinectSensor incremental(options, &scene, Rigid3::Identity());
      KinectSensor full(options, &scene, Rigid3::Identity());
      for (int i = 0; i < 12; ++i) {
        // a goes right, then back left (the projector's shadow falls left of an object, beyond
        // the columns it covered in the last frame); b goes down, then jumps left.
        const double s = 0.15 * i;
        const double a_x = i < 7 ? -0.3 + 0.06 * i : 0.06 - 0.07 * (i - 7);
        scene.SetPose(
            a,
            Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(s, Eigen::Vector3d(1, 2, 3).normalized())),
                   Eigen::Vector3d(a_x, 0.02 * std::sin(s), 0.9)));
        scene.SetPose(b, Rigid3(Eigen::Quaterniond::Identity(),
                                Eigen::Vector3d(i < 8 ? 0.2 : 0.1, -0.1 + 0.01 * i, 1.1)));
        scene.SetVisible(b, i % 4 != 3);
        scene.Commit();
        const RgbdFrame x =
            incremental.Render(i, i == 6 ? RenderMode::kFull : RenderMode::kIncremental);
        const RgbdFrame y = full.Render(i, RenderMode::kFull);
        ASSERT_EQ(x.depth, y.depth) << "frame " << i;
        ASSERT_EQ(x.rgb, y.rgb) << "frame " << i;
      }
      EXPECT_LT(incremental.timings().pixels_recast, full.timings().pixels_recast / 3);
    }
  }
  KinectSensor::SetVectorKernels(true);
}

// The projector's shadow of a moving object falls left of it, the IR camera's right of it: an
// object moving left (right) casts a shadow where neither this frame's nor the last frame's
// object was, which the incremental occlusion windows must reach. A wall alone behind it, so
// that no static shadow hides the difference.
TEST(KinectSensor, IncrementalShadowsOfObjectsMovingEitherWay) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.6, -Eigen::Vector3d::UnitZ()));
  const uint32_t box = scene.AddMoving("box", Box(0.06, 0.3, 0.05));
  scene.Commit();
  for (const bool vector_kernels : {true, false}) {
    SCOPED_TRACE(testing::Message()
                 << "vector kernels " << KinectSensor::SetVectorKernels(vector_kernels));
    KinectSensorOptions options = Statistical();
    KinectSensor incremental(options, &scene, Rigid3::Identity());
    KinectSensor full(options, &scene, Rigid3::Identity());
    for (int i = 0; i < 10; ++i) {
      // Left by about 20 px a frame, then right again.
      const double x = i < 5 ? 0.1 - 0.03 * i : -0.05 + 0.03 * (i - 5);
      scene.SetPose(box, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0, 0.8)));
      scene.Commit();
      const RgbdFrame a = incremental.Render(i, RenderMode::kIncremental);
      const RgbdFrame b = full.Render(i, RenderMode::kFull);
      ASSERT_EQ(a.depth, b.depth) << "frame " << i;
      ASSERT_EQ(a.rgb, b.rgb) << "frame " << i;
    }
  }
  KinectSensor::SetVectorKernels(true);
}

// The moving objects are cast only where their cluster boxes project (pixel centres inside the
// projected hulls): every pixel whose ray hits one must be among them. Oracle: one cast of every
// pixel against the whole scene (RayScene::Target::kAll, instance traversal).
TEST(KinectSensor, MovingObjectsAreCastWhereverTheirRaysHitThem) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.6, -Eigen::Vector3d::UnitZ()));
  const uint32_t a = scene.AddMoving("a", Box(0.1, 0.05, 0.08));
  const uint32_t b = scene.AddMoving("b", Box(0.3, 0.01, 0.02));  // a thin rod
  scene.Commit();
  KinectSensorOptions options = Exact();
  options.missing.projector_shadow = false;
  options.missing.ir_camera_occlusion = false;
  options.missing.grazing_from_deg = 89.9;
  options.missing.grazing_to_deg = 90.0;
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const PinholeIntrinsics& k = sensor.depth_intrinsics();
  HitBuffer hits;
  hits.Resize(k.pixel_count());
  long moving_pixels = 0;
  for (int i = 0; i < 10; ++i) {
    const double s = 0.37 * i;
    scene.SetPose(
        a, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(s, Eigen::Vector3d(1, 2, 3).normalized())),
                  Eigen::Vector3d(-0.35 + 0.07 * i, 0.1 * std::sin(s), 0.7 + 0.05 * i)));
    scene.SetPose(b, Rigid3(Eigen::Quaterniond(
                                Eigen::AngleAxisd(1.1 * s, Eigen::Vector3d(3, 1, 2).normalized())),
                            Eigen::Vector3d(0.1, -0.15 + 0.03 * i, 0.8)));
    scene.Commit();
    const RgbdFrame frame = sensor.Render(i);
    scene.Cast(k, sensor.world_T_depth_camera(), FullImageSpans(k), RayScene::Target::kAll, &hits);
    for (int p = 0; p < k.pixel_count(); ++p) {
      if (hits.object[p] != a && hits.object[p] != b) continue;
      ++moving_pixels;
      const float expected = std::floor(hits.depth[p] * 5000.0f + 0.5f);
      // The object's own BVH and the instance traversal may round the depth differently.
      ASSERT_NEAR(frame.depth[p], expected, 1.0) << "frame " << i << " pixel " << p;
    }
  }
  EXPECT_GT(moving_pixels, 20000);
}

TEST(KinectSensor, FramesAreIndependentOfTheThreadCountAndFollowTheSeed) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.3, -Eigen::Vector3d::UnitZ()));
  const uint32_t a = scene.AddMoving("a", Box(0.1, 0.05, 0.08));
  scene.SetPose(a, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())),
                          Eigen::Vector3d(0.02, 0.01, 0.9)));
  scene.Commit();
  KinectSensorOptions options = Statistical();
  RgbdFrame one, two, other_seed;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    one = sensor.Render(7);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 4);
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    two = sensor.Render(7);
  }
  options.seed = 2;
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  other_seed = sensor.Render(7);
  EXPECT_EQ(one.depth, two.depth);
  EXPECT_EQ(one.rgb, two.rgb);
  EXPECT_NE(one.depth, other_seed.depth);
  EXPECT_NE(one.rgb, other_seed.rgb);
  EXPECT_NE(sensor.Render(8).depth, other_seed.depth);  // a new frame, new noise
}

TEST(KinectSensor, VectorAndPortableKernelsGiveTheSameBytes) {
  // Edges, shadows, grazing angles, a moving object and noise: every branch of the kernels.
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.4, -Eigen::Vector3d::UnitZ()));
  scene.AddStatic("floor", Quad(3, 3),
                  Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(1.45, Eigen::Vector3d::UnitX())),
                         Eigen::Vector3d(0, 0.25, 1.2)));
  const uint32_t a = scene.AddMoving("a", Box(0.1, 0.05, 0.08));
  scene.SetPose(a, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())),
                          Eigen::Vector3d(0.03, -0.02, 0.8)));
  scene.Commit();
  // Colour noise of 1.5 (default), 2.5 and 12: tables of 32, 64 and 512 slots per value (looked
  // up by one or two permutes, or gathered); the structured-light mode (IR noise, matcher).
  for (const auto& [quantise, read_noise, mode] :
       {std::tuple{true, 1.5, SensorMode::kStatistical},
        std::tuple{false, 2.5, SensorMode::kStatistical},
        std::tuple{true, 12.0, SensorMode::kStatistical},
        std::tuple{true, 1.5, SensorMode::kStructuredLight}}) {
    KinectSensorOptions options = Statistical();
    options.mode = mode;
    options.quantise = quantise;
    options.color.read_noise = read_noise;
    options.intrinsics.width = 333;  // rows that do not fill whole vectors
    options.intrinsics.cx = 166;
    KinectSensor vector_sensor(options, &scene, Rigid3::Identity());
    KinectSensor portable_sensor(options, &scene, Rigid3::Identity());
    const bool vector = KinectSensor::SetVectorKernels(true);
    const RgbdFrame x = vector_sensor.Render(4);
    KinectSensor::SetVectorKernels(false);
    const RgbdFrame y = portable_sensor.Render(4);
    KinectSensor::SetVectorKernels(true);
    EXPECT_EQ(x.depth, y.depth) << "vector kernels in use: " << vector;
    EXPECT_EQ(x.rgb, y.rgb);
    EXPECT_GT(std::count(x.depth.begin(), x.depth.end(), 0), 100);
    // On an AVX-512 machine the AVX2 kernels too (elsewhere they were the vector kernels above).
    if (internal::UseAvx512Default() && internal::UseAvx2Default()) {
      KinectSensor avx2_sensor(options, &scene, Rigid3::Identity());
      internal::UseAvx512().store(false);
      const RgbdFrame z = avx2_sensor.Render(4);
      KinectSensor::SetVectorKernels(true);
      EXPECT_EQ(z.depth, y.depth) << "AVX2 kernels";
      EXPECT_EQ(z.rgb, y.rgb) << "AVX2 kernels";
    }
  }
}

// Chi-squared goodness of fit of integer samples (offsets from their clean value) against a
// normal N(0, sigma) rounded to integers (bins k = round(x); tails pooled where expected < 20),
// clamped to [lowest, highest] (the bins at the clamps take the whole tails beyond them).
double RoundedNormalFitP(const std::vector<int>& offsets, double sigma, int lowest = -1000000,
                         int highest = 1000000) {
  std::map<int, long> counts;
  for (int k : offsets) ++counts[k];
  const boost::math::normal normal(0.0, sigma);
  const double n = offsets.size();
  const int limit = static_cast<int>(std::ceil(5 * sigma));
  double chi2 = 0;
  int bins = 0;
  long observed_tail = 0;
  double expected_tail = 0;
  for (int k = std::max(-limit - 20, lowest); k <= std::min(limit + 20, highest); ++k) {
    const double below = k == lowest ? 0.0 : boost::math::cdf(normal, k - 0.5);
    const double up_to = k == highest ? 1.0 : boost::math::cdf(normal, k + 0.5);
    const double expected = n * (up_to - below);
    const long observed = counts.count(k) ? counts[k] : 0;
    if (expected < 20) {
      observed_tail += observed;
      expected_tail += expected;
      continue;
    }
    chi2 += (observed - expected) * (observed - expected) / expected;
    ++bins;
  }
  chi2 += (observed_tail - expected_tail) * (observed_tail - expected_tail) / expected_tail;
  ++bins;
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(bins - 1), chi2));
}

TEST(KinectSensor, DepthNoiseIsNormalWithTheModelledSigma) {
  // quantise off: depth units are z + sigma_z g rounded to 0.2 mm; the offsets from z must follow
  // the rounded N(0, sigma_z) (Box-Muller samples, tested bin by bin).
  const double z = 1.0;
  RayScene scene;
  scene.AddStatic("wall", Quad(30, 30), FacingCamera(z, -Eigen::Vector3d::UnitZ()));
  scene.Commit();
  KinectSensorOptions options = Statistical();
  options.quantise = false;
  options.seed = 5;
  KinectSensor sensor(options, &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(2);
  const int clean = static_cast<int>(std::lround(z / frame.depth_scale));
  std::vector<int> offsets;
  for (uint16_t d : frame.depth) {
    if (d != 0) offsets.push_back(static_cast<int>(d) - clean);
  }
  ASSERT_GT(offsets.size(), 250000u);
  const double sigma_units = options.axial.Sigma(z, 0.0) / frame.depth_scale;
  EXPECT_GT(RoundedNormalFitP(offsets, sigma_units), 1e-3);
}

// Frame 1 of a flat wall of one albedo facing the camera at 1.2 m, with noise and without.
std::pair<RgbdFrame, RgbdFrame> NoisyAndCleanWall(int albedo, KinectSensorOptions options) {
  RayScene scene;
  TriangleMesh wall = Quad(30, 30);
  wall.face_colors.setConstant(2, 3, albedo);
  scene.AddStatic("wall", wall, FacingCamera(1.2, -Eigen::Vector3d::UnitZ()));
  scene.Commit();
  KinectSensor noisy(options, &scene, Rigid3::Identity());
  options.noise = false;
  KinectSensor exact(options, &scene, Rigid3::Identity());
  return {noisy.Render(1), exact.Render(1)};
}

TEST(KinectSensor, ColorNoiseIsNormalWithTheModelledSigmaAndUncorrelated) {
  KinectSensorOptions options = Statistical();
  options.seed = 9;
  const auto [x, clean] = NoisyAndCleanWall(170, options);
  const int value = clean.rgb[0];
  for (uint8_t c : clean.rgb) ASSERT_EQ(c, value);  // flat wall, flat shading
  ASSERT_GT(value, 30);
  ASSERT_LT(value, 225);  // no clipping within 10 sigma
  std::vector<int> offsets(x.rgb.size());
  for (size_t i = 0; i < x.rgb.size(); ++i) offsets[i] = static_cast<int>(x.rgb[i]) - value;
  const double sigma = std::sqrt(options.color.read_noise * options.color.read_noise +
                                 options.color.shot_gain * value);
  EXPECT_GT(RoundedNormalFitP(offsets, sigma), 1e-3);
  // Neighbouring bytes (channels of one pixel, pixels next to each other) are uncorrelated: |r|
  // below 4 standard errors.
  for (int lag : {1, 2, 3}) {
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i + lag < offsets.size(); ++i) {
      sxy += offsets[i] * offsets[i + lag];
      sxx += offsets[i] * offsets[i];
    }
    EXPECT_LT(std::abs(sxy / sxx), 4 / std::sqrt(static_cast<double>(offsets.size())))
        << "lag " << lag;
  }
}

// Near black and near white the noisy bytes clamp: the bins 0 and 255 hold the whole tails.
TEST(KinectSensor, ColorNoiseClampsToTheByteRange) {
  for (int albedo : {2, 252}) {
    KinectSensorOptions options = Statistical();
    options.seed = 21;
    // Linear light factor about 1: the albedo's own (dark or bright) value.
    options.color.ambient = 1.0;
    options.color.diffuse = albedo < 128 ? 0.0 : 0.02;
    const auto [x, clean] = NoisyAndCleanWall(albedo, options);
    const int value = clean.rgb[0];
    for (uint8_t c : clean.rgb) ASSERT_EQ(c, value);
    ASSERT_TRUE(value <= 4 || value >= 251) << value;
    std::vector<int> offsets(x.rgb.size());
    for (size_t i = 0; i < x.rgb.size(); ++i) offsets[i] = static_cast<int>(x.rgb[i]) - value;
    const double sigma = std::sqrt(options.color.read_noise * options.color.read_noise +
                                   options.color.shot_gain * value);
    EXPECT_GT(RoundedNormalFitP(offsets, sigma, -value, 255 - value), 1e-3) << "value " << value;
    const auto clamped = std::count(x.rgb.begin(), x.rgb.end(), value < 128 ? 0 : 255);
    EXPECT_GT(clamped, 1000) << "value " << value;
  }
}

TEST(KinectSensor, FrameParallelRenderingGivesTheSequentialFrames) {
  // Three workers, each with its own scene in the state of the frame it renders.
  auto make_scene = [](RayScene* scene) {
    scene->AddStatic("wall", Quad(10, 10), FacingCamera(1.6, -Eigen::Vector3d::UnitZ()));
    return scene->AddMoving("a", Box(0.1, 0.05, 0.08));
  };
  auto pose = [](RayScene* scene, uint32_t object, int i) {
    scene->SetPose(object,
                   Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitY())),
                          Eigen::Vector3d(-0.2 + 0.05 * i, 0.01 * i, 1.0)));
    scene->Commit();
  };
  KinectSensorOptions options = Statistical();
  for (RenderMode mode : {RenderMode::kIncremental, RenderMode::kFull}) {
    RayScene reference_scene;
    const uint32_t reference_object = make_scene(&reference_scene);
    pose(&reference_scene, reference_object, 0);
    KinectSensor reference(options, &reference_scene, Rigid3::Identity());
    std::vector<RgbdFrame> expected;
    for (int i = 0; i < 9; ++i) {
      pose(&reference_scene, reference_object, i);
      expected.push_back(reference.Render(i, mode));
    }
    std::vector<std::unique_ptr<RayScene>> scenes;
    std::vector<std::unique_ptr<KinectSensor>> sensors;
    std::vector<SensorWorker> workers;
    for (int w = 0; w < 3; ++w) {
      scenes.push_back(std::make_unique<RayScene>());
      const uint32_t object = make_scene(scenes.back().get());
      pose(scenes.back().get(), object, 0);
      sensors.push_back(
          std::make_unique<KinectSensor>(options, scenes.back().get(), Rigid3::Identity()));
      RayScene* scene = scenes.back().get();
      workers.push_back({[=](int i) { pose(scene, object, i); }, sensors.back().get()});
    }
    std::vector<int> order;
    RenderFrames(workers, 0, 9, mode, [&](const RgbdFrame& frame) {
      order.push_back(frame.index);
      ASSERT_EQ(frame.depth, expected[frame.index].depth) << "frame " << frame.index;
      ASSERT_EQ(frame.rgb, expected[frame.index].rgb) << "frame " << frame.index;
    });
    EXPECT_EQ(order, std::vector<int>({0, 1, 2, 3, 4, 5, 6, 7, 8}));
    EXPECT_EQ(TotalTimings(workers).frames, 9u);
  }
}

TEST(KinectSensor, RangeLimitsMakePixelsMissing) {
  RayScene scene;
  scene.AddStatic("far", Quad(40, 40), FacingCamera(4.5, -Eigen::Vector3d::UnitZ()));
  scene.Commit();
  KinectSensor sensor(Exact(), &scene, Rigid3::Identity());
  const RgbdFrame frame = sensor.Render(0);
  for (uint16_t d : frame.depth) ASSERT_EQ(d, 0);
}

TEST(KinectSensor, NonsenseOptionsAreRejectedNamingTheField) {
  RayScene scene;
  scene.AddStatic("wall", Quad(10, 10), FacingCamera(1.0, -Eigen::Vector3d::UnitZ()));
  scene.Commit();
  KinectSensorOptions options = Statistical();
  options.intrinsics.fx = -5;
  try {
    KinectSensor sensor(options, &scene, Rigid3::Identity());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor.intrinsics.fx"));
    EXPECT_THAT(e.what(), HasSubstr("-5"));
  }
  options = Statistical();
  options.max_depth = 0.3;
  EXPECT_THROW(KinectSensor(options, &scene, Rigid3::Identity()), InputError);
  options = Statistical();
  options.missing.edge_probability = 1.5;
  EXPECT_THROW(KinectSensor(options, &scene, Rigid3::Identity()), InputError);
}

}  // namespace
}  // namespace mmh::sim
