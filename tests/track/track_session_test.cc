// A whole tracking run (RunTracking) on in-memory frames: the slider-only mode of annotation
// sessions against the rendered block's true values, and its input errors.
#include "track/track_session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/test_util.h"
#include "tests/track/sim_take.h"

namespace mmh::track {
namespace {

using test_util::ErrorOf;
using ::testing::HasSubstr;

// An annotation session of the Soldier story (participant 3, take 1: the proxy rests outside the
// play area, the hand moves the slider block) read in slider-only mode: no proxy is tracked, the
// slider is read on every frame within 0.3 RMSE of the block's true value.
TEST(TrackSessionTest, SliderOnlyModeReadsAnAnnotationSession) {
  int take_frames = 0;
  test_take::SimTake take = test_take::SoldierStorySession(
      MMH_SOURCE_DIR, 3, 1, sim::RenderSession::kAnnotation, &take_frames);
  const int frames = std::min(take_frames, 150);
  std::vector<double> truth(frames);
  CallbackFrameSource source(
      [&](int i, RgbdFrame* frame) {
        if (i >= frames) return false;
        *frame = take.Render(i, nullptr, &truth[i]);
        return true;
      },
      "annotation session", frames);
  TrackConfig config;
  config.track.proxy = false;
  // No model: slider-only mode does not build one.
  const TrackRun run = RunTracking(source, TriangleMesh(), "", take.Setup(), true, config);
  ASSERT_EQ(static_cast<int>(run.frames.size()), frames);
  ASSERT_EQ(static_cast<int>(run.annotation.values.size()), frames);
  EXPECT_TRUE(run.trajectory.empty());
  EXPECT_EQ(run.summary.tracked, 0);
  EXPECT_EQ(run.summary.lost, frames);
  for (const TrackFrameResult& r : run.frames) {
    EXPECT_EQ(r.status, TrackStatus::kLost);
    EXPECT_EQ(r.reason, "proxy not tracked");
  }
  // The table frame from the estimated plane (once), near the calibration's.
  ASSERT_TRUE(run.camera_T_table && run.table_plane);
  EXPECT_LT((run.camera_T_table->translation - take.Setup().camera_T_table->translation).norm(),
            0.01);
  EXPECT_EQ(run.summary.slider_found, frames);
  double sum = 0.0;
  for (int i = 0; i < frames; ++i) sum += std::pow(run.annotation.values[i] - truth[i], 2);
  const double rmse = std::sqrt(sum / frames);
  const auto [lo, hi] = std::minmax_element(truth.begin(), truth.end());
  std::printf("slider-only RMSE %.3f over %d frames (true values %.2f..%.2f), %.0f frames/s\n",
              rmse, frames, *lo, *hi, frames / run.summary.seconds);
  EXPECT_GT(*hi - *lo, 2.0);  // the block moves
  EXPECT_LE(rmse, 0.3);
}

TEST(TrackSessionTest, SliderOnlyModeNeedsALikeBoxAndTheSlider) {
  test_take::SimTake take;
  CallbackFrameSource source([&](int, RgbdFrame*) { return false; }, "none", 0);
  TrackConfig config;
  config.track.proxy = false;
  EXPECT_THAT(
      ErrorOf([&] { RunTracking(source, TriangleMesh(), "", take.Setup(), false, config); }),
      HasSubstr("no setup calibration was given"));
  TrackSetup no_box = take.Setup();
  no_box.like_box_length = 0;
  EXPECT_THAT(ErrorOf([&] { RunTracking(source, TriangleMesh(), "", no_box, true, config); }),
              HasSubstr("like_box_length is 0"));
  config.track.slider = false;
  EXPECT_THAT(ErrorOf([&] { RunTracking(source, TriangleMesh(), "", take.Setup(), true, config); }),
              HasSubstr("track.slider"));
}

}  // namespace
}  // namespace mmh::track

namespace mmh::track {
namespace {

// A box 27 x 87 x 71 mm turned about an oblique axis and moved: its smallest width is its 27 mm
// side (the brute-force reference: the box's own extents), found to 0.01 mm whatever the turn; a
// regular tetrahedron of edge a has smallest width a / sqrt(2) (between opposite edges).
TEST(TrackSessionTest, SmallestWidthOfATurnedBoxAndATetrahedron) {
  const Eigen::Vector3f half(0.0135f, 0.0435f, 0.0355f);
  for (double angle : {0.0, 0.3, 1.1, 2.5}) {
    const Eigen::Matrix3f turn =
        Eigen::AngleAxisf(static_cast<float>(angle), Eigen::Vector3f(1, 2, 3).normalized())
            .toRotationMatrix();
    TriangleMesh box;
    box.vertices.resize(8, 3);
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3f corner((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(),
                                   (i & 4 ? 1 : -1) * half.z());
      box.vertices.row(i) = (turn * corner + Eigen::Vector3f(0.2f, -0.1f, 0.5f)).transpose();
    }
    EXPECT_NEAR(SmallestWidth(box), 0.027, 1e-5) << angle;
  }
  TriangleMesh tetrahedron;
  tetrahedron.vertices.resize(4, 3);
  tetrahedron.vertices << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  tetrahedron.vertices *= 0.01f;  // edge 2 sqrt(2) cm
  EXPECT_NEAR(SmallestWidth(tetrahedron), 0.02, 1e-5);
}

TEST(TrackSessionTest, MinHeightWarningWhenTheModelLyingFlatIsCutOff) {
  // The YCB-Video gelatin box (27 mm thin) under the real preset's 3 cm cut: warned, naming the
  // option, the value and the thickness; the foam brick (50 mm) and the default 8 mm cut: not.
  const std::string warning = MinHeightWarning(0.0269, 0.03);
  EXPECT_THAT(warning, HasSubstr("tracker.segmentation.min_height = 0.03 m"));
  EXPECT_THAT(warning, HasSubstr("0.0269 m thick"));
  EXPECT_EQ(MinHeightWarning(0.0502, 0.03), "");
  EXPECT_EQ(MinHeightWarning(0.0269, 0.008), "");
  EXPECT_NE(MinHeightWarning(0.0399, 0.03), "");  // 9.9 mm above the cut: less than 1 cm
}

}  // namespace
}  // namespace mmh::track
