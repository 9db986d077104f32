// Tests of sim/fakenect_writer.h: the dump's files byte by byte, the raw-disparity conversion, and
// playback through Debian's real fakenect library (dlopen'ed; skipped when it is absent).
#include "sim/fakenect_writer.h"

#include <dlfcn.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <libfreenect.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/image_io.h"
#include "tests/test_util.h"

namespace mmh::sim {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr const char* kFakenectLibrary = "/usr/lib/x86_64-linux-gnu/fakenect/libfreenect.so.0.5";
constexpr size_t kPixels = 640 * 480;

using test_util::ErrorOf;
using test_util::ReadBytes;
using test_util::TempDir;

std::vector<uint16_t> RandomRaw(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<uint16_t> raw(kPixels);
  for (auto& v : raw) v = static_cast<uint16_t>(rng() % 2048);  // includes 2047 = no reading
  raw[0] = 2047;
  raw[1] = 0;
  raw[2] = 0x0102;  // byte order visible in the file
  return raw;
}

std::vector<uint8_t> RandomRgb(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> rgb(3 * kPixels);
  for (auto& v : rgb) v = static_cast<uint8_t>(rng());
  return rgb;
}

TEST(FakenectWriterTest, KinectTimestamps) {
  EXPECT_EQ(KinectTimestampFromSeconds(0.0), 0u);
  EXPECT_EQ(KinectTimestampFromSeconds(1.0 / 30), 2000000u);
  EXPECT_EQ(KinectTimestampFromSeconds(1.0), 60000000u);
  // The 32-bit counter wraps after 2^32 / 60 MHz = 71.58 s.
  EXPECT_EQ(KinectTimestampFromSeconds(4294967296.0 / 60e6), 0u);
  EXPECT_EQ(KinectTimestampFromSeconds(4294967297.0 / 60e6), 1u);
}

TEST(FakenectWriterTest, WritesTheRecordFormat) {
  TempDir dir;
  const auto raw = RandomRaw(1);
  const auto rgb = RandomRgb(2);
  FakenectTiltState tilt;
  tilt.accelerometer_x = -3;
  tilt.accelerometer_y = 819;
  tilt.accelerometer_z = 0x0102;
  tilt.tilt_angle = -30;
  tilt.tilt_status = 4;
  {
    FakenectWriter writer(dir / "dump", tilt);
    writer.Add(1.5, raw, rgb);
    writer.Add(0.5, raw, rgb);  // INDEX.txt is sorted by time
    EXPECT_FALSE(fs::exists(dir / "dump"));
    writer.Finish();
  }
  EXPECT_EQ(ReadBytes(dir / "dump" / "INDEX.txt"),
            "d-0.500000-30000000.pgm\nr-0.500000-30000000.ppm\na-0.500000-30000000.dump\n"
            "d-1.500000-90000000.pgm\nr-1.500000-90000000.ppm\na-1.500000-90000000.dump\n");
  const std::string depth = ReadBytes(dir / "dump" / "d-1.500000-90000000.pgm");
  ASSERT_EQ(depth.size(), 17 + 2 * kPixels);
  EXPECT_EQ(depth.substr(0, 17), "P5 640 480 65535\n");
  EXPECT_EQ(depth.substr(17, 6), std::string("\xff\x07\x00\x00\x02\x01", 6));  // little-endian
  // The NYU raw reader reads fakenect dumps.
  EXPECT_EQ(ReadNyuRawDisparity(dir / "dump" / "d-1.500000-90000000.pgm").values, raw);
  const std::string video = ReadBytes(dir / "dump" / "r-0.500000-30000000.ppm");
  ASSERT_EQ(video.size(), 15 + 3 * kPixels);
  EXPECT_EQ(video.substr(0, 15), "P6 640 480 255\n");
  EXPECT_EQ(video.substr(15), std::string(rgb.begin(), rgb.end()));
  const std::string accel = ReadBytes(dir / "dump" / "a-0.500000-30000000.dump");
  EXPECT_EQ(accel, std::string("\xfd\xff\x33\x03\x02\x01\xe2\x00\x04\x00\x00\x00", 12));
  const auto marker = nlohmann::json::parse(ReadBytes(dir / "dump" / "fakenect.json"));
  EXPECT_EQ(marker["writer"], "mmh");
  EXPECT_EQ(marker["frames"], 2);
}

TEST(FakenectWriterTest, ChecksInputAndStaging) {
  TempDir dir;
  const auto rgb = RandomRgb(3);
  {
    FakenectWriter writer(dir / "bad");
    auto raw = RandomRaw(4);
    raw[640 * 2 + 5] = 2048;
    EXPECT_THAT(ErrorOf([&] { writer.Add(0.0, raw, rgb); }),
                HasSubstr("frame at 0 s, depth pixel (5, 2): got 2048, expected a raw 11-bit"));
    EXPECT_THAT(ErrorOf([&] { writer.Add(0.0, std::vector<uint16_t>(10), rgb); }),
                HasSubstr("got 10 pixels, expected 307200 = 640x480"));
    EXPECT_THAT(ErrorOf([&] { writer.Add(0.0, RandomRaw(5), std::vector<uint8_t>(3)); }),
                HasSubstr("rgb: got 3 bytes"));
    EXPECT_THAT(ErrorOf([&] { writer.Add(-1.0, RandomRaw(5), rgb); }), HasSubstr("finite seconds"));
    writer.Add(2.0, RandomRaw(5), rgb);
    EXPECT_THAT(ErrorOf([&] { writer.Add(2.0000001, RandomRaw(5), rgb); }),
                HasSubstr("the record time 2.000000 of another frame"));
  }  // destroyed without Finish(): nothing left
  EXPECT_FALSE(fs::exists(dir / "bad"));
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir / "")) ++entries;
  EXPECT_EQ(entries, 0);
  // A folder mmh did not write is never replaced.
  fs::create_directories(dir / "theirs");
  std::ofstream(dir / "theirs" / "INDEX.txt") << "d-1.0-1.pgm\n";
  EXPECT_THAT(ErrorOf([&] { FakenectWriter writer(dir / "theirs"); }),
              HasSubstr("an existing folder that mmh did not write"));
}

TEST(FakenectWriterTest, RawDisparityOfLatticeDepthsIsExact) {
  const KinectCalibration calibration;
  RgbdFrame frame;
  frame.depth_intrinsics.width = 1100;
  frame.depth_intrinsics.height = 1;
  frame.depth.resize(1100);
  // Lattice depths of raw 0..1060 (0.32 to 10.7 m) in TUM units come back as their raw value.
  for (int raw = 0; raw <= 1060; ++raw) {
    frame.depth[raw] =
        static_cast<uint16_t>(std::lround(DepthFromRaw(raw, calibration) / frame.depth_scale));
  }
  frame.depth[1061] = 0;                                                // missing
  frame.depth[1062] = static_cast<uint16_t>(0.25 / frame.depth_scale);  // nearer than raw 0
  const std::vector<uint16_t> raw = RawDisparityFromDepth(frame, calibration);
  ASSERT_EQ(raw.size(), 1100u);
  for (int r = 0; r <= 1060; ++r) ASSERT_EQ(raw[r], r) << r;
  EXPECT_EQ(raw[1061], 2047);
  EXPECT_EQ(raw[1062], 2047);
  frame.depth.pop_back();
  EXPECT_THAT(ErrorOf([&] { RawDisparityFromDepth(frame, calibration); }),
              HasSubstr("got 1099 pixels"));
}

// --- Playback through Debian's fakenect library ------------------------------------------------

struct Playback {
  std::vector<std::vector<uint16_t>> depth;
  std::vector<uint32_t> depth_timestamps;
  std::vector<std::vector<uint8_t>> video;
  std::vector<uint32_t> video_timestamps;
};
Playback* g_playback = nullptr;

void OnDepth(freenect_device*, void* data, uint32_t timestamp) {
  const auto* samples = static_cast<const uint16_t*>(data);
  g_playback->depth.emplace_back(samples, samples + kPixels);
  g_playback->depth_timestamps.push_back(timestamp);
}

void OnVideo(freenect_device*, void* data, uint32_t timestamp) {
  const auto* bytes = static_cast<const uint8_t*>(data);
  g_playback->video.emplace_back(bytes, bytes + 3 * kPixels);
  g_playback->video_timestamps.push_back(timestamp);
}

template <class F>
F Symbol(void* library, const char* name) {
  void* symbol = dlsym(library, name);
  EXPECT_NE(symbol, nullptr) << name;
  return reinterpret_cast<F>(symbol);
}

TEST(FakenectWriterTest, DebianFakenectPlaysTheDumpBack) {
  if (!fs::exists(kFakenectLibrary)) GTEST_SKIP() << "no " << kFakenectLibrary;
  TempDir dir;
  constexpr int kFrames = 4;
  constexpr double kStart = 10.0, kPeriod = 1.0 / 30;
  std::vector<std::vector<uint16_t>> raws;
  std::vector<std::vector<uint8_t>> rgbs;
  FakenectTiltState tilt;
  tilt.accelerometer_y = 819;
  tilt.tilt_angle = 10;
  {
    FakenectWriter writer(dir / "dump", tilt);
    for (int i = 0; i < kFrames; ++i) {
      raws.push_back(RandomRaw(10 + i));
      rgbs.push_back(RandomRgb(20 + i));
      writer.Add(kStart + i * kPeriod, raws.back(), rgbs.back());
    }
    writer.Finish();
  }

  // fakenect reads FAKENECT_PATH when it starts; its state is static, so load it afresh.
  ASSERT_EQ(::setenv("FAKENECT_PATH", (dir / "dump").c_str(), 1), 0);
  ASSERT_EQ(::setenv("FAKENECT_LOOP", "0", 1), 0);  // upstream master loops by default
  void* library = dlopen(kFakenectLibrary, RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(library, nullptr) << dlerror();
  auto init = Symbol<decltype(&freenect_init)>(library, "freenect_init");
  auto open_device = Symbol<decltype(&freenect_open_device)>(library, "freenect_open_device");
  auto find_depth_mode =
      Symbol<decltype(&freenect_find_depth_mode)>(library, "freenect_find_depth_mode");
  auto set_depth_mode =
      Symbol<decltype(&freenect_set_depth_mode)>(library, "freenect_set_depth_mode");
  auto find_video_mode =
      Symbol<decltype(&freenect_find_video_mode)>(library, "freenect_find_video_mode");
  auto set_video_mode =
      Symbol<decltype(&freenect_set_video_mode)>(library, "freenect_set_video_mode");
  auto set_depth_callback =
      Symbol<decltype(&freenect_set_depth_callback)>(library, "freenect_set_depth_callback");
  auto set_video_callback =
      Symbol<decltype(&freenect_set_video_callback)>(library, "freenect_set_video_callback");
  auto set_video_buffer =
      Symbol<decltype(&freenect_set_video_buffer)>(library, "freenect_set_video_buffer");
  auto start_depth = Symbol<decltype(&freenect_start_depth)>(library, "freenect_start_depth");
  auto start_video = Symbol<decltype(&freenect_start_video)>(library, "freenect_start_video");
  auto process_events =
      Symbol<decltype(&freenect_process_events)>(library, "freenect_process_events");
  auto get_tilt_state =
      Symbol<decltype(&freenect_get_tilt_state)>(library, "freenect_get_tilt_state");
  auto get_tilt_degs = Symbol<decltype(&freenect_get_tilt_degs)>(library, "freenect_get_tilt_degs");
  auto stop_depth = Symbol<decltype(&freenect_stop_depth)>(library, "freenect_stop_depth");
  auto stop_video = Symbol<decltype(&freenect_stop_video)>(library, "freenect_stop_video");
  auto shutdown = Symbol<decltype(&freenect_shutdown)>(library, "freenect_shutdown");
  ASSERT_FALSE(::testing::Test::HasFailure());

  Playback playback;
  g_playback = &playback;
  freenect_context* context = nullptr;
  freenect_device* device = nullptr;
  ASSERT_EQ(init(&context, nullptr), 0);
  ASSERT_EQ(open_device(context, &device, 0), 0);
  const freenect_frame_mode depth_mode =
      find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT);
  EXPECT_EQ(depth_mode.width, 640);
  EXPECT_EQ(depth_mode.height, 480);
  EXPECT_EQ(depth_mode.bytes, 640 * 480 * 2);
  EXPECT_EQ(depth_mode.data_bits_per_pixel, 11);
  ASSERT_EQ(set_depth_mode(device, depth_mode), 0);
  ASSERT_EQ(set_video_mode(device, find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB)),
            0);
  // Depth without a buffer of ours (fakenect lends its own), video into ours.
  std::vector<uint8_t> video_buffer(3 * kPixels);
  ASSERT_EQ(set_video_buffer(device, video_buffer.data()), 0);
  set_depth_callback(device, OnDepth);
  set_video_callback(device, OnVideo);
  ASSERT_EQ(start_depth(device), 0);
  ASSERT_EQ(start_video(device), 0);

  const auto begin = std::chrono::steady_clock::now();
  // One INDEX.txt line per call: depth, video, accelerometer per frame.
  for (int call = 0; call < 3 * kFrames; ++call) {
    ASSERT_GE(process_events(context), 0) << "call " << call;
    if (call == 2) {
      freenect_raw_tilt_state* state = get_tilt_state(device);
      EXPECT_EQ(state->accelerometer_y, 819);
      EXPECT_EQ(state->tilt_angle, 10);
      EXPECT_EQ(get_tilt_degs(state), 5.0);
    }
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  stop_depth(device);
  stop_video(device);
  shutdown(context);
  dlclose(library);
  ::unsetenv("FAKENECT_PATH");
  ::unsetenv("FAKENECT_LOOP");
  g_playback = nullptr;

  ASSERT_EQ(playback.depth.size(), static_cast<size_t>(kFrames));
  ASSERT_EQ(playback.video.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_TRUE(playback.depth[i] == raws[i]) << "depth frame " << i;
    EXPECT_TRUE(playback.video[i] == rgbs[i]) << "video frame " << i;
    const uint32_t expected = KinectTimestampFromSeconds(kStart + i * kPeriod);
    EXPECT_EQ(playback.depth_timestamps[i], expected);
    EXPECT_EQ(playback.video_timestamps[i], expected);
  }
  // fakenect paces playback by the record times: 3 periods between the first and last frame.
  EXPECT_GT(elapsed, 0.9 * (kFrames - 1) * kPeriod);
}

}  // namespace
}  // namespace mmh::sim
