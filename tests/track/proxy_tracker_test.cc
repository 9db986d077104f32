// Accuracy of the proxy tracker on simulated takes (full Kinect noise, the hand holding the proxy)
// against the simulator's ground truth, and its loss detection and recovery.
#include "track/proxy_tracker.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>
#include <optional>
#include <vector>

#include "metrics/tracking_metrics.h"
#include "tests/track/sim_take.h"

namespace mmh::track {
namespace {

struct TakeResult {
  metrics::TrackingSummary summary;
  std::vector<TrackFrameResult> frames;
};

TakeResult TrackTake(test_take::SimTake& take, int frames,
                     const ProxyTrackerOptions& options = {}) {
  ProxyTracker tracker(take.model(), "soldier", take.Setup(), options);
  std::vector<std::optional<Rigid3>> estimates;
  std::vector<Rigid3> truth;
  TakeResult result;
  for (int i = 0; i < frames; ++i) {
    Rigid3 camera_T_proxy;
    const RgbdFrame frame = take.Render(i, &camera_T_proxy);
    const TrackFrameResult r = tracker.Track(frame);
    result.frames.push_back(r);
    truth.push_back(camera_T_proxy);
    if (r.status != TrackStatus::kLost) {
      estimates.push_back(r.camera_T_proxy);
    } else {
      estimates.push_back(std::nullopt);
    }
  }
  const auto points = metrics::MetricPoints(take.model());
  const metrics::PoseErrorOptions metric_options;
  const auto errors = metrics::ComputePoseErrors(estimates, truth, points, metric_options);
  result.summary = metrics::SummarizeTracking(errors, metrics::Diameter(points), metric_options);
  for (size_t i = 0; i < errors.size(); ++i) {
    if (!errors[i].success) {
      std::printf(
          "frame %zu %s rot %.2f trans %.4f pts %d skin %d share %.2f rms %.4f fs %.2f det %d %s\n",
          i, TrackStatusName(result.frames[i].status), errors[i].rotation_deg,
          errors[i].translation, result.frames[i].points, result.frames[i].skin_points,
          result.frames[i].inlier_share, result.frames[i].rms,
          result.frames[i].free_space_violation, result.frames[i].detected,
          result.frames[i].reason.c_str());
    }
  }
  std::printf("%s\n", metrics::ToJson(result.summary).dump().c_str());
  return result;
}

TEST(ProxyTrackerTest, DemoWalkWithHand) {
  test_take::SimTake take;
  const TakeResult result = TrackTake(take, 150);
  EXPECT_LE(result.summary.median_rotation_deg, 1.0);
  EXPECT_LE(result.summary.median_translation, 0.002);
  EXPECT_GE(result.summary.success_rate, 0.99);
}

}  // namespace
}  // namespace mmh::track
