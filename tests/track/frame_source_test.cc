// Frame sources: the in-memory stream, TUM RGB-D folders (ours and public ones by name), and the
// libfreenect capture code run unchanged against Debian's fakenect library on a dump the simulator
// wrote (in a child process: the dynamic loader takes fakenect's libfreenect.so.0.5 from
// LD_LIBRARY_PATH instead of the real one this test binary is linked with).
#include "track/frame_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/image_io.h"
#include "core/rgbd_folder.h"
#include "sim/fakenect_writer.h"
#include "sim/kinect_model.h"
#include "tests/test_util.h"
#include "tests/track/sim_take.h"
#include "track/freenect_source.h"
#include "track/proxy_tracker.h"

namespace mmh::track {
namespace {

namespace fs = std::filesystem;
using test_util::ErrorOf;
using test_util::TempDir;
using ::testing::HasSubstr;

constexpr const char* kFakenectDir = "/usr/lib/x86_64-linux-gnu/fakenect";

TEST(FrameSourceTest, CallbackStreamEndsWhenTheProducerSaysSo) {
  test_take::SimTake take;
  CallbackFrameSource source(
      [&](int i, RgbdFrame* frame) {
        if (i >= 3) return false;
        *frame = take.Render(i);
        return true;
      },
      "simulator");
  RgbdFrame frame;
  int count = 0;
  while (source.Next(&frame)) {
    EXPECT_EQ(frame.index, count);
    EXPECT_EQ(frame.depth.size(), 640u * 480u);
    ++count;
  }
  EXPECT_EQ(count, 3);
  EXPECT_EQ(source.Describe(), "simulator");
  // With a known length the source stops there.
  CallbackFrameSource bounded([&](int, RgbdFrame*) { return true; }, "x", 2);
  EXPECT_TRUE(bounded.Next(&frame));
  EXPECT_TRUE(bounded.Next(&frame));
  EXPECT_FALSE(bounded.Next(&frame));
}

TEST(FrameSourceTest, FolderFramesAreTheRenderedOnesAndABadImageLosesOneFrame) {
  TempDir dir;
  test_take::SimTake take;
  std::vector<RgbdFrame> rendered;
  {
    RgbdCameraInfo camera;
    RgbdFolderWriter writer(dir / "take", camera);
    for (int i = 0; i < 4; ++i) {
      rendered.push_back(take.Render(i));
      writer.Add(rendered.back());
    }
    writer.Finish();
  }
  // Truncate frame 2's depth image.
  const auto depth_files = [&] {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir / "take" / "depth")) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
  }();
  ASSERT_EQ(depth_files.size(), 4u);
  fs::resize_file(depth_files[2], fs::file_size(depth_files[2]) / 2);

  FolderFrameSource source(dir / "take");
  EXPECT_EQ(source.size(), 4);
  EXPECT_THAT(source.Describe(), HasSubstr("folder"));
  ProxyTracker tracker(take.model(), "soldier", take.Setup(), ProxyTrackerOptions());
  RgbdFrame frame;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(source.Next(&frame));
    EXPECT_EQ(frame.index, i);
    EXPECT_DOUBLE_EQ(frame.timestamp, rendered[i].timestamp);
    if (i == 2) {
      EXPECT_TRUE(frame.depth.empty());
      EXPECT_THAT(source.frame_error(), HasSubstr(depth_files[2].filename().string()));
      const TrackFrameResult lost = tracker.Unreadable(frame, source.frame_error());
      EXPECT_EQ(lost.status, TrackStatus::kLost);
      EXPECT_THAT(lost.reason, HasSubstr("unreadable frame"));
      continue;
    }
    EXPECT_TRUE(source.frame_error().empty());
    EXPECT_TRUE(frame.depth == rendered[i].depth) << i;  // bit-identical
    EXPECT_TRUE(frame.rgb == rendered[i].rgb) << i;
    EXPECT_EQ(tracker.Track(frame).status, TrackStatus::kTracked) << i;
  }
  EXPECT_FALSE(source.Next(&frame));
}

TEST(FrameSourceTest, PublicTumFoldersTakeTheirIntrinsicsFromTheName) {
  TempDir dir;
  const fs::path real = fs::path(MMH_SOURCE_DIR) / ".." / "shared" / "data" / "real-rgbd";
  if (!fs::exists(real / "TUM_depth.png")) GTEST_SKIP() << "no real frames at " << real;
  // A public-layout folder (no camera.json): the freiburg number selects the intrinsics.
  const fs::path folder = dir / "rgbd_dataset_freiburg1_desk";
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  fs::copy_file(real / "TUM_color.png", folder / "rgb" / "1.000000.png");
  fs::copy_file(real / "TUM_depth.png", folder / "depth" / "1.000000.png");
  std::ofstream(folder / "rgb.txt") << "# rgb\n1.000000 rgb/1.000000.png\n";
  std::ofstream(folder / "depth.txt") << "# depth\n1.000000 depth/1.000000.png\n";
  FolderFrameSource source(folder);
  RgbdFrame frame;
  ASSERT_TRUE(source.Next(&frame));
  EXPECT_DOUBLE_EQ(frame.depth_intrinsics.fx, 517.3);
  EXPECT_DOUBLE_EQ(frame.depth_intrinsics.cy, 255.3);
  // Without the name and without intrinsics it cannot be read.
  fs::rename(folder, dir / "some_sequence");
  EXPECT_THAT(ErrorOf([&] { FolderFrameSource s(dir / "some_sequence"); }),
              HasSubstr("intrinsics"));
}

TEST(FreenectSourceTest, RawDisparityLawMatchesTheSensorModel) {
  const sim::KinectCalibration calibration;  // the simulator's Kinect
  const FreenectOptions options;             // the same constants
  for (int raw = 0; raw < 2047; ++raw) {
    const double z = sim::DepthFromRaw(raw, calibration);
    const double units = std::round(z / kTumDepthScale);
    const uint16_t expected = units >= 1 && units <= 65535 ? static_cast<uint16_t>(units) : 0;
    ASSERT_EQ(DepthUnitsFromRaw(raw, options, kTumDepthScale), expected) << raw;
  }
  EXPECT_EQ(DepthUnitsFromRaw(2047, options, kTumDepthScale), 0);
  FreenectOptions bad;
  bad.intrinsics.width = 320;
  EXPECT_THAT(ErrorOf([&] { bad.Validate("freenect"); }), HasSubstr("640x480"));
}

// Runs in the child process only (MMH_FAKENECT_OUT set): captures every frame of the fakenect dump
// through FreenectFrameSource and writes them as a TUM folder.
TEST(FreenectSourceTest, ChildCapturesTheDump) {
  const char* out = std::getenv("MMH_FAKENECT_OUT");
  if (!out) GTEST_SKIP() << "runs as the child of FakenectPlaysTheSimulatorsDump";
  FreenectFrameSource source{FreenectOptions()};
  RgbdCameraInfo camera;
  RgbdFolderWriter writer(out, camera);
  RgbdFrame frame;
  int frames = 0;
  while (source.Next(&frame)) {
    writer.Add(frame);
    ++frames;
  }
  ASSERT_GT(frames, 0);
  writer.Finish();
}

TEST(FreenectSourceTest, FakenectPlaysTheSimulatorsDump) {
  if (!fs::exists(fs::path(kFakenectDir) / "libfreenect.so.0.5")) {
    GTEST_SKIP() << "Debian's fakenect library is not installed";
  }
  TempDir dir;
  test_take::SimTake take;
  const sim::KinectCalibration calibration;
  std::vector<RgbdFrame> rendered;
  {
    sim::FakenectWriter writer(dir / "dump");
    for (int i = 0; i < 5; ++i) {
      rendered.push_back(take.Render(i));
      writer.Add(rendered.back().timestamp,
                 sim::RawDisparityFromDepth(rendered.back(), calibration), rendered.back().rgb);
    }
    writer.Finish();
  }
  const std::string command = "FAKENECT_PATH=" + (dir / "dump").string() +
                              " FAKENECT_LOOP=0 LD_LIBRARY_PATH=" + kFakenectDir +
                              " MMH_FAKENECT_OUT=" + (dir / "captured").string() + " /proc/" +
                              std::to_string(::getpid()) +
                              "/exe --gtest_filter=FreenectSourceTest.ChildCapturesTheDump > " +
                              (dir / "child.log").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << test_util::ReadBytes(dir / "child.log");

  RgbdFolderReader captured(dir / "captured");
  ASSERT_EQ(captured.size(), 5);
  for (int i = 0; i < 5; ++i) {
    const RgbdFrame frame = captured.Read(i);
    EXPECT_NEAR(frame.timestamp, rendered[i].timestamp, 1e-6) << i;
    EXPECT_TRUE(frame.rgb == rendered[i].rgb) << i;
    // Depth: the raw disparity's lattice depth, within one TUM unit of the rendered depth.
    const auto raw = sim::RawDisparityFromDepth(rendered[i], calibration);
    int mismatches = 0;
    for (size_t p = 0; p < raw.size(); ++p) {
      const double units = std::round(sim::DepthFromRaw(raw[p], calibration) / kTumDepthScale);
      const uint16_t expected = raw[p] == 2047 ? 0 : static_cast<uint16_t>(units);
      mismatches += frame.depth[p] != expected;
      if (expected != 0) {
        ASSERT_LE(std::abs(frame.depth[p] - rendered[i].depth[p]), 1)
            << "frame " << i << " pixel " << p;
      }
    }
    EXPECT_EQ(mismatches, 0) << i;
  }
}

TEST(FreenectSourceTest, AbsentDeviceIsAClearError) {
  // This process uses the real libfreenect: no Kinect is attached to the test machine (when one
  // is, ask for a device index beyond it).
  FreenectOptions options;
  options.device_index = 7;
  const std::string error = ErrorOf([&] { FreenectFrameSource source(options); });
  EXPECT_THAT(error, HasSubstr("freenect"));
  EXPECT_THAT(error, ::testing::AnyOf(HasSubstr("device(s)"), HasSubstr("could not be")));
}

}  // namespace
}  // namespace mmh::track
