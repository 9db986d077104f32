// The per-frame table of tracked takes: what it measures (checked against the definitions on a
// known motion), that its CSV reads back to the same doubles, that the error model fitted from the
// table equals the fit from the trajectories, and that a bad file is an InputError naming the
// line and column.
#include "pipeline/tracking_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"
#include "pipeline/error_model.h"
#include "tests/test_util.h"

namespace mmh::pipeline {
namespace {

constexpr double kPi = 3.14159265358979323846;
const Eigen::Vector3d kCamera(0.0, -0.65, 0.55);

// The proxy circles the table's origin at radius 0.1 m, 0.3 rad/s, turning with its path, at 30 fps.
Trajectory Circle(int frames) {
  Trajectory circle;
  for (int t = 0; t < frames; ++t) {
    const double s = t / 30.0, angle = 0.3 * s;
    circle.timestamps.push_back(s);
    circle.poses.emplace_back(Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())),
                              Eigen::Vector3d(0.1 * std::cos(angle), 0.1 * std::sin(angle), 0.05));
  }
  return circle;
}

struct Take {
  Trajectory truth, tracked;
  std::vector<track::TrackStatus> status;
  Annotation slider_truth, slider_read;
  std::vector<bool> found;
};

// A take tracked by the error model (with spikes, flips and losses), its slider read likewise.
Take SimulatedTake(int frames, std::uint64_t seed) {
  Take take;
  take.truth = Circle(frames);
  ErrorModelOptions options;
  options.view = ViewRates::Uniform({.loss_rate = 0.01,
                                     .loss_mean_frames = 3,
                                     .flip_rate = 0.005,
                                     .flip_mean_frames = 5,
                                     .spike_rate = 0.05,
                                     .spike_mean_frames = 2});
  options.slider_miss_share = 0.1;
  SimulatedTracking tracking = SimulateTracking(take.truth, options, seed, kCamera);
  take.tracked = tracking.tracked;
  take.status = tracking.status;
  take.slider_truth.timestamps = take.truth.timestamps;
  for (int t = 0; t < frames; ++t) take.slider_truth.values.push_back(4 * std::sin(t / 20.0));
  SimulatedReading reading = SimulateSliderReading(take.slider_truth, options, seed + 1);
  take.slider_read = reading.read;
  take.found = reading.found;
  return take;
}

TakeFrames Measure(const Take& take, const std::string& animator, int index, bool slider = true) {
  const TrackingObservation tracking{&take.truth, &take.tracked, &take.status, kCamera};
  const ReadingObservation reading{&take.slider_truth, &take.slider_read, &take.found};
  return MeasureTakeFrames(animator, index, tracking, slider ? &reading : nullptr);
}

TEST(TrackingFramesTest, MeasuresTheViewTheSpeedAndTheError) {
  const Take take = SimulatedTake(300, 7);
  const TakeFrames frames = Measure(take, "A01", 2);
  ASSERT_EQ(frames.frames.size(), 300u);
  EXPECT_EQ(frames.animator, "A01");
  EXPECT_EQ(frames.take, 2);
  // On the circle: chord 2 r sin(ω dt / 2) per frame, turn ω dt.
  const double dt = 1.0 / 30.0;
  const double speed = 2 * 0.1 * std::sin(0.3 * dt / 2) / dt;
  int lost = 0;
  for (std::size_t t = 0; t < frames.frames.size(); ++t) {
    const TrackingFrame& f = frames.frames[t];
    EXPECT_NEAR(f.speed, speed, 1e-12) << t;
    EXPECT_NEAR(f.turn_rate, 0.3, 1e-9) << t;
    EXPECT_NEAR(f.tilt_deg, 0.0, 1e-6) << t;
    // The heading's sector is the view condition.
    EXPECT_EQ(ViewConditionOf(f.heading_deg, f.tilt_deg, 45.0),
              ViewCondition(take.truth.poses[t], kCamera, 45.0));
    EXPECT_EQ(f.status, take.status[t]);
    EXPECT_TRUE(f.has_slider);
    EXPECT_EQ(f.slider_read, take.slider_read.values[t]);
    if (f.status == track::TrackStatus::kLost) {
      ++lost;
      for (double e : f.error) EXPECT_EQ(e, 0.0);
      continue;
    }
    // The error from its definition: tracked = truth · (Exp(r), e).
    const Eigen::Vector3d r(f.error[0], f.error[1], f.error[2]);
    const Eigen::Quaterniond q =
        r.norm() > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(r.norm(), r.normalized()))
                     : Eigen::Quaterniond::Identity();
    const Rigid3 rebuilt = take.truth.poses[t] * Rigid3(q, Eigen::Vector3d(f.error[3], f.error[4],
                                                                             f.error[5]));
    EXPECT_LT((rebuilt.translation - take.tracked.poses[t].translation).norm(), 1e-12) << t;
    EXPECT_LT(rebuilt.rotation.angularDistance(take.tracked.poses[t].rotation), 1e-9) << t;
  }
  EXPECT_GT(lost, 0);
  // The heading: 0 where the proxy's x axis points at the camera.
  Rigid3 facing(Eigen::Quaterniond(Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitZ())),
                Eigen::Vector3d(0, 0, 0));
  EXPECT_NEAR(ProxyHeadingDeg(facing, kCamera), 0.0, 1e-9);
  facing.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(ProxyHeadingDeg(facing, kCamera), 90.0, 1e-9);
}

TEST(TrackingFramesTest, TheCsvReadsBackToTheSameDoublesAndTheSameFit) {
  std::vector<Take> takes;
  for (int i = 0; i < 4; ++i) takes.push_back(SimulatedTake(2000, 100 + i));
  std::vector<TakeFrames> frames;
  std::vector<TrackingObservation> tracking;
  std::vector<ReadingObservation> readings;
  for (int i = 0; i < 4; ++i) {
    // The last take has no slider reading (a practice take is not annotated).
    frames.push_back(Measure(takes[i], i < 2 ? "A01" : "A02", i % 2, i < 3));
    tracking.push_back({&takes[i].truth, &takes[i].tracked, &takes[i].status, kCamera});
    if (i < 3) {
      readings.push_back({&takes[i].slider_truth, &takes[i].slider_read, &takes[i].found});
    }
  }
  test_util::TempDir dir;
  const auto path = dir / "tracking_errors.csv";
  test_util::WriteText(path, TakeFramesCsv(frames));
  const std::vector<TakeFrames> again = ReadTakeFramesCsv(path);
  ASSERT_EQ(again.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(again[i].animator, frames[i].animator);
    EXPECT_EQ(again[i].take, frames[i].take);
    ASSERT_EQ(again[i].frames.size(), frames[i].frames.size());
    for (std::size_t t = 0; t < frames[i].frames.size(); ++t) {
      const TrackingFrame& a = frames[i].frames[t];
      const TrackingFrame& b = again[i].frames[t];
      EXPECT_EQ(std::memcmp(&a.error, &b.error, sizeof a.error), 0) << i << " " << t;
      EXPECT_EQ(a.time, b.time);
      EXPECT_EQ(a.status, b.status);
      EXPECT_EQ(a.heading_deg, b.heading_deg);
      EXPECT_EQ(a.tilt_deg, b.tilt_deg);
      EXPECT_EQ(a.speed, b.speed);
      EXPECT_EQ(a.turn_rate, b.turn_rate);
      EXPECT_EQ(a.has_slider, b.has_slider);
      EXPECT_EQ(a.slider_truth, b.slider_truth);
      EXPECT_EQ(a.slider_read, b.slider_read);
      EXPECT_EQ(a.slider_found, b.slider_found);
    }
  }
  EXPECT_EQ(TakeFramesCsv(again), TakeFramesCsv(frames));
  // The fit from the file is the fit from the trajectories, number for number.
  const ErrorModelEstimate direct = EstimateErrorModel(tracking, readings);
  const ErrorModelEstimate from_file = EstimateErrorModel(again);
  EXPECT_EQ(from_file.ToJson(), direct.ToJson());
  EXPECT_GT(direct.flip_episodes, 0);
  EXPECT_GT(direct.loss_episodes, 0);
  EXPECT_EQ(direct.slider_frames, 3 * 2000);
}

// The message of the InputError ReadTakeFramesCsv throws for `text`.
std::string ReadError(const std::string& text) {
  test_util::TempDir dir;
  const auto path = dir / "frames.csv";
  test_util::WriteText(path, text);
  try {
    ReadTakeFramesCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(TrackingFramesTest, ABadFileNamesTheLineAndColumn) {
  const Take take = SimulatedTake(3, 1);
  const std::string good = TakeFramesCsv({Measure(take, "A01", 0)});
  const std::string header = good.substr(0, good.find('\n') + 1);
  const std::string row0 = "A01,0,0,0,tracked,10,0,0,0,0.01,0,0,0.001,0,0,0.5,0.4,1\n";

  EXPECT_NE(ReadError("").find("expected the header"), std::string::npos);
  EXPECT_NE(ReadError("a,b\n").find("frames.csv:1: the header is 'a,b'"), std::string::npos);
  EXPECT_NE(ReadError(header + "A01,0,0\n").find("frames.csv:2: 3 fields, expected 18"),
            std::string::npos);
  std::string bad = row0;
  bad.replace(bad.find("tracked"), 7, "tracking");
  EXPECT_NE(ReadError(header + bad).find(
                "frames.csv:2: column status is 'tracking', expected tracked, predicted or lost"),
            std::string::npos)
      << ReadError(header + bad);
  EXPECT_NE(ReadError(header + row0 + "A01,0,2" + row0.substr(7)).find(
                "frames.csv:3: column frame is '2', expected 1"),
            std::string::npos)
      << ReadError(header + row0 + "A01,0,2" + row0.substr(7));
  EXPECT_NE(ReadError(header + "A01,0,0,0,tracked,nan,0,0,0,0,0,0,0,0,0,,,\n")
                .find("column heading_deg is 'nan', expected a finite number"),
            std::string::npos);
  EXPECT_NE(ReadError(header + "A01,0,0,0,lost,10,0,0,0,0.01,,,,,,,,\n")
                .find("column error_rx_rad is '0.01', expected empty (the frame is lost)"),
            std::string::npos);
  EXPECT_NE(ReadError(header + "A01,0,0,0,tracked,10,0,0,0,0,0,0,0,0,0,0.5,0.4,yes\n")
                .find("column slider_found is 'yes', expected 0 or 1"),
            std::string::npos);
  EXPECT_NE(ReadError(header + row0 + "A01,0,1,0,tracked,10,0,0,0,0,0,0,0,0,0,,,\n")
                .find("frames.csv:3: column slider_truth"),
            std::string::npos);
  EXPECT_NE(ReadError(header + "A01,-1,0,0,tracked,10,0,0,0,0,0,0,0,0,0,,,\n")
                .find("column take is '-1', expected a whole number >= 0"),
            std::string::npos);
  EXPECT_EQ(ReadError(good), "no error");
}

TEST(TrackingFramesTest, MismatchedLengthsNameTheTake) {
  Take take = SimulatedTake(10, 1);
  take.found.pop_back();
  try {
    Measure(take, "A03", 1);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("animator A03, take 1: slider truth, read and found "
                                         "lengths (10, 10, 9) differ from the take's 10 frames"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mmh::pipeline
