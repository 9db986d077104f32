// The appearance check (track/appearance.h) on a synthetic frame: a flat plate printed half dark
// red, half light blue, seen at 0.5 m under another white balance and exposure. Its colours
// agree with the image at the true pose and disagree at the half turn that depth cannot tell from
// it; a model without colours, or of one colour, is refused naming the file.
#include "track/appearance.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace mmh::track {
namespace {

using ::testing::HasSubstr;

constexpr int kCells = 20;
constexpr float kSize = 0.1f;  // the plate's side [m]

// The plate in its own frame: z = 0, facing -z (towards a camera on its -z side), x from -5 to
// 5 cm; the half x < 0 dark red, the other light blue.
TriangleMesh Plate() {
  TriangleMesh mesh;
  mesh.vertices.resize((kCells + 1) * (kCells + 1), 3);
  for (int j = 0; j <= kCells; ++j) {
    for (int i = 0; i <= kCells; ++i) {
      mesh.vertices.row(j * (kCells + 1) + i) << kSize * (static_cast<float>(i) / kCells - 0.5f),
          kSize * (static_cast<float>(j) / kCells - 0.5f), 0.0f;
    }
  }
  mesh.faces.resize(2 * kCells * kCells, 3);
  mesh.face_colors.resize(2 * kCells * kCells, 3);
  for (int j = 0; j < kCells; ++j) {
    for (int i = 0; i < kCells; ++i) {
      const uint32_t a = j * (kCells + 1) + i, b = a + 1, c = a + kCells + 1, d = c + 1;
      const int f = 2 * (j * kCells + i);
      // Counter-clockwise seen from -z: normal -z.
      mesh.faces.row(f) << a, c, b;
      mesh.faces.row(f + 1) << b, c, d;
      for (int k = f; k <= f + 1; ++k) {
        if (i < kCells / 2) {
          mesh.face_colors.row(k) << 120, 20, 30;
        } else {
          mesh.face_colors.row(k) << 150, 190, 230;
        }
      }
    }
  }
  return mesh;
}

// The plate straight ahead at 0.5 m: depth 0.5 m where it is, the colours with another gain and
// offset per channel (the sensor's white balance and exposure) where x < 0 or x >= 0.
RgbdFrame PlateFrame() {
  RgbdFrame frame;
  const PinholeIntrinsics k;
  frame.depth_intrinsics = frame.color_intrinsics = k;
  frame.depth.assign(static_cast<size_t>(k.width) * k.height, 0);
  frame.rgb.assign(frame.depth.size() * 3, 40);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double x = (u - k.cx) / k.fx * 0.5, y = (v - k.cy) / k.fy * 0.5;
      if (std::abs(x) > kSize / 2 || std::abs(y) > kSize / 2) continue;
      const size_t p = static_cast<size_t>(v) * k.width + u;
      frame.depth[p] = static_cast<uint16_t>(std::lround(0.5 / frame.depth_scale));
      const int base[3] = {x < 0 ? 120 : 150, x < 0 ? 20 : 190, x < 0 ? 30 : 230};
      const double gain[3] = {0.7, 0.9, 0.5}, offset[3] = {10, 5, 30};
      for (int c = 0; c < 3; ++c) {
        frame.rgb[3 * p + c] = static_cast<uint8_t>(std::lround(gain[c] * base[c] + offset[c]));
      }
    }
  }
  return frame;
}

TEST(AppearanceModelTest, TellsAHalfTurnThatDepthCannotSee) {
  const AppearanceModel model(Plate(), "plate");
  EXPECT_EQ(model.size(), static_cast<size_t>(2 * kCells * kCells));
  const RgbdFrame frame = PlateFrame();
  const AppearanceOptions options;
  const Rigid3 truth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 0.5));
  // The half turn about the plate's normal: the same depth, red and blue swapped.
  const Rigid3 turned(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitZ())),
                      Eigen::Vector3d(0, 0, 0.5));
  const std::optional<double> right = model.Agreement(frame, truth, options);
  const std::optional<double> wrong = model.Agreement(frame, turned, options);
  ASSERT_TRUE(right && wrong);
  // Measured 0.9917 and -0.9917 (2026-11-28; the gain and offset per channel keep the
  // chromaticities from matching exactly): pure arithmetic on a synthetic frame, so the bounds
  // allow 0.01 for other compilers only.
  EXPECT_GT(*right, 0.98);
  EXPECT_LT(*wrong, -0.98);
  // Seen from behind (turned over about x: the plate faces away), nothing is seen.
  const Rigid3 back(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX())),
                    Eigen::Vector3d(0, 0, 0.5));
  EXPECT_FALSE(model.Agreement(frame, back, options));
  // Too far from the measured depth (2 cm behind it): hidden, nothing seen.
  EXPECT_FALSE(model.Agreement(frame, Rigid3(truth.rotation, Eigen::Vector3d(0, 0, 0.52)), options));
  // Without a colour image: no agreement.
  RgbdFrame grey = frame;
  grey.rgb.clear();
  EXPECT_FALSE(model.Agreement(grey, truth, options));
}

TEST(AppearanceModelTest, RefusesAModelWithoutAPattern) {
  TriangleMesh plate = Plate();
  SetColor(&plate, kDefaultMeshColor);
  try {
    AppearanceModel model(plate, "box.ply");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("box.ply: the appearance model has no colours"));
  }
  SetColor(&plate, {200, 10, 10});
  try {
    AppearanceModel model(plate, "red.ply");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("red.ply: every face of the appearance model has the colour 200, 10, 10"));
  }
}

TEST(AppearanceOptionsTest, ValidatesItsFields) {
  AppearanceOptions options;
  options.Validate("tracker.appearance");
  options.depth_tolerance = 0;
  EXPECT_THROW(options.Validate("tracker.appearance"), InputError);
  options = {};
  options.margin = -0.1;
  EXPECT_THROW(options.Validate("tracker.appearance"), InputError);
  options = {};
  options.min_samples = 2;
  EXPECT_THROW(options.Validate("tracker.appearance"), InputError);
}

}  // namespace
}  // namespace mmh::track
