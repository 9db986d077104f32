// `mmh track` end to end: a rendered take tracked from its folder (accuracy against its
// groundtruth.txt and slider.csv through the files), reproducible outputs, the libfreenect path on
// a fakenect dump, and bad input (clear errors or per-frame lost, never a crash or a silent pose).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/annotation.h"
#include "core/image_io.h"
#include "core/mesh_io.h"
#include "core/triangle_mesh.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;
using ::testing::HasSubstr;

// One rendered take shared by the tests (rendering is the slow part).
const fs::path& RenderedTake() {
  static TempDir dir;  // removed at exit
  static const fs::path take = [] {
    const fs::path out = dir / "take";
    // (On structured-light frames, the default, the first detection comes on the third frame.)
    const auto result =
        RunMmh("render --quiet --out " + out.string() + " --set render.frames=60 " +
               "--set render.fakenect=true" + test_util::StatisticalFramesFlags());
    EXPECT_EQ(result.exit_code, 0) << result.output;
    return out;
  }();
  return take;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(TrackCliTest, TracksARenderedTakeFromItsFolder) {
  const fs::path take = RenderedTake();
  TempDir dir;
  const auto result = RunMmh("track --input " + take.string() + " --model " +
                             (take / "model.ply").string() + " --out " + (dir / "out").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("60 tracked"));
  for (const char* name : {"trajectory.tum", "status.csv", "annotation.csv", "track_summary.json",
                           "config.resolved.json", "run.json"}) {
    EXPECT_TRUE(fs::exists(dir / "out" / name)) << name;
  }
  // Against the renderer's ground truth, through the files.
  const Trajectory tracked = ReadTum(dir / "out" / "trajectory.tum");
  const Trajectory truth = ReadTum(take / "groundtruth.txt");
  ASSERT_EQ(tracked.size(), truth.size());
  int within = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(tracked.timestamps[i], truth.timestamps[i]);
    const double angle = RotationAngle(tracked.poses[i].rotation, truth.poses[i].rotation);
    const double distance = (tracked.poses[i].translation - truth.poses[i].translation).norm();
    within += angle < 5 * M_PI / 180 && distance < 0.01;
  }
  EXPECT_GE(within, 59);
  const Annotation slider = ReadAnnotationCsv(dir / "out" / "annotation.csv");
  const Annotation slider_truth = ReadAnnotationCsv(take / "slider.csv");
  ASSERT_EQ(slider.size(), slider_truth.size());
  double sum = 0.0;
  for (size_t i = 0; i < slider.size(); ++i)
    sum += std::pow(slider.values[i] - slider_truth.values[i], 2);
  EXPECT_LE(std::sqrt(sum / slider.size()), 0.3);
  const auto status = Lines(ReadBytes(dir / "out" / "status.csv"));
  ASSERT_EQ(status.size(), 61u);
  EXPECT_THAT(status[0], HasSubstr("frame,timestamp,status"));
  EXPECT_THAT(status[1], HasSubstr(",tracked,1,"));  // detected on the first frame
  // Same input and config: the same bytes (timings only in run.json).
  const auto again = RunMmh("track --quiet --input " + take.string() + " --model " +
                            (take / "model.ply").string() + " --out " + (dir / "again").string() +
                            " --set track.output_frame=camera");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  for (const char* name : {"trajectory.tum", "status.csv", "annotation.csv", "track_summary.json",
                           "config.resolved.json"}) {
    EXPECT_EQ(ReadBytes(dir / "out" / name), ReadBytes(dir / "again" / name)) << name;
  }
  // The outputs were staged beside --out and moved into place whole: no staging folder is left.
  for (const auto& e : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
  }
  // A folder that mmh did not write is refused before the work, and left as it was.
  fs::create_directories(dir / "theirs");
  test_util::WriteText(dir / "theirs" / "notes.txt", "mine");
  const auto theirs = RunMmh("track --quiet --input " + take.string() + " --model " +
                             (take / "model.ply").string() + " --out " + (dir / "theirs").string());
  EXPECT_EQ(theirs.exit_code, 2) << theirs.output;
  EXPECT_THAT(theirs.output, HasSubstr("theirs"));
  EXPECT_EQ(ReadBytes(dir / "theirs" / "notes.txt"), "mine");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "theirs"), fs::directory_iterator()), 1);
}

// An annotation session (the proxy rests outside the play area, the hand moves the slider block):
// the default mode tracks no proxy (exit 1); slider-only mode (track.proxy=false, no model needed)
// exits 0 with annotation.csv within 0.3 RMSE of the rendered block's values and no trajectory.
TEST(TrackCliTest, SliderOnlyModeOnAnAnnotationSession) {
  TempDir dir;
  const fs::path take = dir / "annotation";
  const std::string source = MMH_SOURCE_DIR;
  auto render = RunMmh("render --quiet --config " + source +
                       "/configs/study_soldier.json --set scenario.story=\\\"" + source +
                       "/configs/stories/soldier.json\\\" --set scenario.animator=3 --set "
                       "render.take=1 --set render.session=annotation --set render.frames=30 "
                       "--out " +
                       take.string());
  ASSERT_EQ(render.exit_code, 0) << render.output;
  const std::string input = "track --input " + take.string() + " --out ";
  auto tracked = RunMmh(input + (dir / "proxy").string() + " --model " +
                        (take / "model.ply").string() + " --set track.max_frames=5");
  EXPECT_EQ(tracked.exit_code, 1) << tracked.output;
  auto slider = RunMmh(input + (dir / "slider").string() + " --set track.proxy=false");
  ASSERT_EQ(slider.exit_code, 0) << slider.output;
  EXPECT_THAT(slider.output, HasSubstr("proxy not tracked (track.proxy=false); slider found in 30"));
  EXPECT_FALSE(fs::exists(dir / "slider" / "trajectory.tum"));
  const Annotation read = ReadAnnotationCsv(dir / "slider" / "annotation.csv");
  const Annotation truth = ReadAnnotationCsv(take / "slider.csv");
  ASSERT_EQ(read.size(), truth.size());
  double sum = 0.0;
  for (size_t i = 0; i < read.size(); ++i) sum += std::pow(read.values[i] - truth.values[i], 2);
  EXPECT_LE(std::sqrt(sum / read.size()), 0.3);
  const auto status = Lines(ReadBytes(dir / "slider" / "status.csv"));
  ASSERT_EQ(status.size(), 31u);
  EXPECT_THAT(status[1], HasSubstr(",lost,0,0,0,0,0,0,1,"));
  EXPECT_THAT(status[1], HasSubstr("proxy not tracked"));
  // Without the setup calibration (no Like box to read): a clear error, nothing written.
  fs::remove(take / "scene.json");
  auto no_setup = RunMmh(input + (dir / "none").string() + " --set track.proxy=false");
  EXPECT_EQ(no_setup.exit_code, 2) << no_setup.output;
  EXPECT_THAT(no_setup.output, HasSubstr("needs a setup calibration with a Like box"));
  EXPECT_FALSE(fs::exists(dir / "none" / "status.csv"));
  // The proxy mode still needs the model.
  auto no_model = RunMmh(input + (dir / "none").string());
  EXPECT_EQ(no_model.exit_code, 2) << no_model.output;
  EXPECT_THAT(no_model.output, HasSubstr("--model is required"));
}

TEST(TrackCliTest, TableFrameOutput) {
  const fs::path take = RenderedTake();
  TempDir dir;
  const auto result = RunMmh("track --quiet --input " + take.string() + " --model " +
                             (take / "model.ply").string() + " --out " + (dir / "out").string() +
                             " --set track.output_frame=table --set track.max_frames=10");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const Trajectory tracked = ReadTum(dir / "out" / "trajectory.tum");
  ASSERT_EQ(tracked.size(), 10u);
  // table_T_proxy: the Soldier stands on the table, its origin (the bottom) within 2 cm of it.
  for (const Rigid3& pose : tracked.poses) {
    EXPECT_LT(std::abs(pose.translation.z()), 0.02);
    EXPECT_LT(pose.translation.head<2>().norm(), 0.2);
  }
}

// The tracker for the statistical frames of RenderedTake (with the default skin growth this take's
// first detection verifies a pose 2.7 cm off in frame 0).
const std::string kStatisticalFramesTracker =
    " --set " + test_util::StatisticalFramesTrackerSetting();

TEST(TrackCliTest, FreenectInputRunsOnAFakenectDump) {
  const fs::path dump = RenderedTake().string() + ".fakenect";
  if (!fs::exists("/usr/lib/x86_64-linux-gnu/fakenect/libfreenect.so.0.5") || !fs::exists(dump)) {
    GTEST_SKIP() << "no fakenect library or dump";
  }
  TempDir dir;
  const auto result =
      RunMmh("track --input freenect --model " + (RenderedTake() / "model.ply").string() +
             " --setup " + (RenderedTake() / "scene.json").string() + " --out " +
             (dir / "out").string() + " --set track.max_frames=20 2>&1; true");
  // The real libfreenect: no Kinect here, a clear error.
  EXPECT_THAT(result.output, HasSubstr("freenect"));
  const std::string with_fakenect =
      "FAKENECT_PATH=" + dump.string() +
      " FAKENECT_LOOP=0 LD_LIBRARY_PATH=/usr/lib/x86_64-linux-gnu/fakenect " +
      std::string(MMH_BINARY) + " track --input freenect --model " +
      (RenderedTake() / "model.ply").string() + " --setup " +
      (RenderedTake() / "scene.json").string() + " --out " + (dir / "live").string() +
      " --set track.max_frames=20" + kStatisticalFramesTracker + " > " + (dir / "log").string() +
      " 2>&1";
  ASSERT_EQ(std::system(with_fakenect.c_str()), 0) << ReadBytes(dir / "log");
  EXPECT_THAT(ReadBytes(dir / "log"), HasSubstr("20 frames from freenect device 0: 20 tracked"));
  const Trajectory tracked = ReadTum(dir / "live" / "trajectory.tum");
  const Trajectory truth = ReadTum(RenderedTake() / "groundtruth.txt");
  for (size_t i = 0; i < tracked.size(); ++i) {
    EXPECT_NEAR(tracked.timestamps[i], truth.timestamps[i], 1e-6);
    EXPECT_LT((tracked.poses[i].translation - truth.poses[i].translation).norm(), 0.01) << i;
  }
}

TEST(TrackCliTest, AbsentDeviceAndBadArgumentsAreClearErrors) {
  const fs::path take = RenderedTake();
  TempDir dir;
  const std::string model = " --model " + (take / "model.ply").string();
  const std::string out = " --out " + (dir / "out").string();
  auto device = RunMmh("track --input freenect" + model + out);
  EXPECT_EQ(device.exit_code, 2) << device.output;
  EXPECT_THAT(device.output, HasSubstr("freenect"));
  auto missing = RunMmh("track --input " + (dir / "nothing").string() + model + out);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.output, HasSubstr("a TUM RGB-D folder or 'freenect'"));
  auto no_model =
      RunMmh("track --input " + take.string() + " --model " + (dir / "x.ply").string() + out);
  EXPECT_EQ(no_model.exit_code, 2);
  EXPECT_THAT(no_model.output, HasSubstr("x.ply"));
  auto typo =
      RunMmh("track --input " + take.string() + model + out + " --set tracker.icp.max_iteration=3");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_THAT(typo.output, HasSubstr("did you mean 'max_iterations'"));
  auto range =
      RunMmh("track --input " + take.string() + model + out + " --set tracker.icp.huber=-1");
  EXPECT_EQ(range.exit_code, 2);
  EXPECT_THAT(range.output, HasSubstr("tracker.icp.huber"));
  // A public-layout folder without intrinsics.
  fs::create_directories(dir / "seq" / "rgb");
  fs::create_directories(dir / "seq" / "depth");
  test_util::WriteText(dir / "seq" / "rgb.txt", "1.0 rgb/1.png\n");
  test_util::WriteText(dir / "seq" / "depth.txt", "1.0 depth/1.png\n");
  auto intrinsics = RunMmh("track --input " + (dir / "seq").string() + model + out);
  EXPECT_EQ(intrinsics.exit_code, 2) << intrinsics.output;
  EXPECT_THAT(intrinsics.output, HasSubstr("intrinsics"));
  EXPECT_FALSE(fs::exists(dir / "out" / "trajectory.tum"));
}

// A copy of the first frames of the take with some frames spoilt.
fs::path SpoiltTake(const TempDir& dir) {
  const fs::path take = RenderedTake();
  const fs::path copy = dir / "spoilt";
  fs::copy(take, copy, fs::copy_options::recursive);
  return copy;
}

TEST(TrackCliTest, BadFramesAreLostNotFatal) {
  TempDir dir;
  const fs::path take = SpoiltTake(dir);
  std::vector<fs::path> depth, rgb;
  for (const auto& e : fs::directory_iterator(take / "depth")) depth.push_back(e.path());
  for (const auto& e : fs::directory_iterator(take / "rgb")) rgb.push_back(e.path());
  std::sort(depth.begin(), depth.end());
  std::sort(rgb.begin(), rgb.end());
  // Frame 5: all depth missing. Frame 10: a truncated PNG. Frame 15: the wrong size.
  DepthImage blank{640, 480, std::vector<uint16_t>(640 * 480, 0)};
  WriteDepthPng16(depth[5], blank);
  fs::resize_file(depth[10], fs::file_size(depth[10]) / 3);
  WriteDepthPng16(depth[15], DepthImage{320, 240, std::vector<uint16_t>(320 * 240, 5000)});
  const auto result =
      RunMmh("track --input " + take.string() + " --model " + (take / "model.ply").string() +
             " --out " + (dir / "out").string() + " --set track.max_frames=30");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto status = Lines(ReadBytes(dir / "out" / "status.csv"));
  ASSERT_EQ(status.size(), 31u);
  EXPECT_THAT(status[6], HasSubstr(",lost,"));
  EXPECT_THAT(status[6], HasSubstr("depth all missing"));
  EXPECT_THAT(status[11], HasSubstr(",lost,"));
  EXPECT_THAT(status[11], HasSubstr("unreadable frame"));
  EXPECT_THAT(status[16], HasSubstr(",lost,"));
  EXPECT_THAT(status[16], HasSubstr("expected 640x480"));
  EXPECT_THAT(status[20], HasSubstr(",tracked,"));  // recovered
  // Lost frames have no pose in the trajectory.
  EXPECT_EQ(ReadTum(dir / "out" / "trajectory.tum").size(), 27u);
}

TEST(TrackCliTest, AModelThatDoesNotMatchIsLostEverywhere) {
  const fs::path take = RenderedTake();
  TempDir dir;
  // A 25 cm cube is no Soldier.
  TriangleMesh cube;
  cube.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    cube.vertices.row(i) << (i & 1 ? 0.125f : -0.125f), (i & 2 ? 0.125f : -0.125f),
        (i & 4 ? 0.25f : 0.0f);
  }
  const uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  cube.faces.resize(12, 3);
  for (int f = 0; f < 12; ++f) cube.faces.row(f) << faces[f][0], faces[f][1], faces[f][2];
  cube.face_colors.setConstant(12, 3, 200);
  WritePly(cube, dir / "cube.ply");
  const auto result =
      RunMmh("track --input " + take.string() + " --model " + (dir / "cube.ply").string() +
             " --out " + (dir / "out").string() + " --set track.max_frames=10");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("no frame was tracked"));
  const auto status = Lines(ReadBytes(dir / "out" / "status.csv"));
  ASSERT_EQ(status.size(), 11u);
  for (size_t i = 1; i < status.size(); ++i) EXPECT_THAT(status[i], HasSubstr(",lost,")) << i;
  EXPECT_FALSE(fs::exists(dir / "out" / "trajectory.tum"));
}

}  // namespace
}  // namespace mmh
