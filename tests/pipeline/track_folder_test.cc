// TrackToFolder (pipeline/track_folder.h) on the committed real YCB-Video frames: the folder holds
// the tracker's run, the followed object's ground truth and its poses as BOP results; bad input
// is refused before the first frame and leaves nothing.
#include "pipeline/track_folder.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "core/config.h"
#include "core/error.h"
#include "core/tum_io.h"
#include "metrics/bop_results.h"
#include "tests/test_util.h"
#include "track/recording.h"

namespace mmh::pipeline {
namespace {

namespace fs = std::filesystem;
using test_util::ErrorOf;
using test_util::ListDir;
using test_util::TempDir;

const fs::path kReal = test_util::RealYcbvDir();
const fs::path kVideo = test_util::RealYcbvVideo();

track::TrackConfig RealConfig(const std::vector<std::string>& sets) {
  Config config = Config::Load(fs::path(MMH_SOURCE_DIR) / "configs" / "track_real.json");
  for (const std::string& set : sets) config.Set(set);
  return track::TrackConfig::FromConfig(config);
}

TEST(TrackFolderTest, ARecordingsFolderHoldsTheRunTruthAndBopResults) {
  TempDir dir;
  const TrackInputs inputs{kVideo.string(), (kReal / "models" / "061_foam_brick.obj").string(), ""};
  const track::TrackConfig config = RealConfig({"track.object=21", "track.init=\"truth\""});
  int progress_calls = 0;
  TrackFolderOptions options;
  options.progress = [&](std::int64_t done, std::int64_t total) {
    ++progress_calls;
    EXPECT_LE(done, total);
  };
  const fs::path out = dir / "track";
  const TrackFolderResult result = TrackToFolder(inputs, config, out, options);
  EXPECT_EQ(result.run.summary.frames, 10);
  EXPECT_EQ(progress_calls, 10);
  EXPECT_EQ(result.run.summary.init, "truth");
  EXPECT_FALSE(result.calibrated);
  EXPECT_EQ(ListDir(out),
            (std::vector<std::string>{"config.resolved.json", "groundtruth.tum", "results_bop.csv",
                                      "run.json", "status.csv", "track_summary.json",
                                      "trajectory.tum"}));
  // groundtruth.tum is the recording's truth of the followed object.
  const Trajectory truth = track::RecordingFrameSource(kVideo).Truth(21);
  const Trajectory written = ReadTum(out / "groundtruth.tum");
  ASSERT_EQ(written.size(), truth.size());
  EXPECT_NEAR((written.poses[4].translation - truth.poses[4].translation).norm(), 0.0, 1e-6);
  // One BOP result per frame not lost, for object 21 of scene 0.
  const std::vector<metrics::BopResult> bop = metrics::ReadBopResults(out / "results_bop.csv");
  EXPECT_EQ(static_cast<int>(bop.size()),
            result.run.summary.tracked + result.run.summary.predicted);
  for (const metrics::BopResult& r : bop) EXPECT_EQ(r.obj_id, 21);
  // Without a provenance callback run.json still marks the folder as mmh's.
  const auto run = nlohmann::json::parse(test_util::ReadBytes(out / "run.json"));
  EXPECT_EQ(run["writer"], "mmh");
}

TEST(TrackFolderTest, BadInputIsRefusedBeforeTheFirstFrame) {
  TempDir dir;
  const fs::path out = dir / "track";
  const std::string brick = (kReal / "models" / "061_foam_brick.obj").string();
  // A model 1000 times too big (millimetres read as metres).
  const TrackInputs big{kVideo.string(), brick, ""};
  EXPECT_NE(ErrorOf([&] {
              TrackToFolder(big, RealConfig({"track.object=21", "track.model_scale=1000"}), out, {});
            }).find("track.max_model_size"),
            std::string::npos);
  // An object the recording does not annotate.
  EXPECT_NE(ErrorOf([&] { TrackToFolder(big, RealConfig({"track.object=99"}), out, {}); })
                .find("track.object"),
            std::string::npos);
  // No model while tracking the proxy; an input that is not a folder.
  EXPECT_NE(ErrorOf([&] { TrackToFolder({kVideo.string(), "", ""}, RealConfig({}), out, {}); })
                .find("--model"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              TrackToFolder({(dir / "nowhere").string(), brick, ""}, RealConfig({}), out, {});
            }).find("--input"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(ListDir(dir.path()).empty());  // no staging folder left behind
}

}  // namespace
}  // namespace mmh::pipeline
