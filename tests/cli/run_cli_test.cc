// `mmh run` and `mmh regress` through the binary.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_util.h"

namespace mmh {
namespace {

using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;
using test_util::WriteText;

const std::string kSource = MMH_SOURCE_DIR;
const std::string kStory = "--set 'scenario.story=\"" + kSource + "/configs/stories/soldier.json\"' ";

// Two 70-frame takes of the Soldier, rendered, tracked, read and composited.
std::string ShortRun(const std::filesystem::path& out, const std::string& extra = "") {
  return "run --config " + kSource + "/configs/soldier.json " + kStory +
         "--set render.frames=70 --set run.takes=2 --quiet --out " + out.string() + " " + extra;
}

TEST(RunCliTest, WritesEveryResultAndTheSameBytesForAnyThreadCount) {
  TempDir dir;
  const auto one = RunMmh(ShortRun(dir / "one", "--threads 1"));
  ASSERT_EQ(one.exit_code, 0) << one.output;
  EXPECT_EQ(one.output, "");  // --quiet
  const auto two = RunMmh(ShortRun(dir / "two", "--threads 2"));
  ASSERT_EQ(two.exit_code, 0) << two.output;
  for (const char* file :
       {"metrics.json", "metrics.csv", "tracking_frames.csv", "tracking_errors.csv", "seams.csv",
        "config.resolved.json",
        "takes/take_0/truth.tum", "takes/take_0/tracked.tum", "takes/take_0/status.csv",
        "takes/take_0/truth_annotation.csv", "takes/take_1/read_annotation.csv",
        "takes/take_1/quality.csv", "montage/montage.tum", "montage/segments.csv",
        "montage/summary.json", "montage_truth/montage.tum"}) {
    ASSERT_TRUE(std::filesystem::exists(dir / "one" / file)) << file;
    EXPECT_EQ(ReadBytes(dir / "one" / file), ReadBytes(dir / "two" / file)) << file;
  }
  const nlohmann::json run = nlohmann::json::parse(ReadBytes(dir / "one/run.json"));
  EXPECT_EQ(run["seconds"]["rendered_frames"], 280);
  EXPECT_GT(run["seconds"]["render_track_frames_per_second"].get<double>(), 0.0);
  EXPECT_NE(ReadBytes(dir / "one/metrics.csv").find("takes,0,tracking.rotation_deg.median,"),
            std::string::npos);
  // Every tracked frame against its truth (the study's format): one row per frame of the two
  // takes, and the error model fits from it.
  const std::string errors = ReadBytes(dir / "one/tracking_errors.csv");
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1 + 2 * 70);
  EXPECT_EQ(errors.find("\nA01,0,0,"), errors.find('\n'));
  const auto fit = RunMmh("error-model --frames " + (dir / "one/tracking_errors.csv").string() +
                          " --quiet --out " + (dir / "fit").string());
  EXPECT_EQ(fit.exit_code, 0) << fit.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "fit/error_model.json"));
}

TEST(RunCliTest, BadInputExitsTwoAndWritesNothing) {
  TempDir dir;
  auto r = RunMmh("run --config " + kSource +
                  "/configs/soldier.json --set 'scenario.story=\"nowhere/story.json\"' --out " +
                  (dir / "a").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nowhere/story.json"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "a"));
  r = RunMmh(ShortRun(dir / "b", "--set run.fidelity=approximate"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("run.fidelity"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
}

// Every frame lost: the run fails (exit 1) naming the take, and keeps what the sessions produced.
TEST(RunCliTest, FailedTrackingKeepsTheFinishedStages) {
  TempDir dir;
  const auto r = RunMmh("run --config " + kSource + "/configs/soldier.json " + kStory +
                        "--set render.frames=20 --set run.takes=2 "
                        "--set montage.labelling.min_segment_length=10 "
                        "--set tracker.verification.max_rms=1e-9 --quiet --out " +
                        (dir / "out").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("take 0: tracking failed"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "out/takes/take_0/status.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out/takes/take_1/read_annotation.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "out/config.resolved.json"));
  EXPECT_NE(ReadBytes(dir / "out/run.json").find("\"failed\": true"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "out/metrics.json"));
}

// --resume reuses the finished takes (a montage option may change), removes what a killed writer
// left, and refuses a folder whose config or files do not belong to the run.
TEST(RunCliTest, ResumeReusesFinishedTakesAndRefusesInconsistentOnes) {
  TempDir dir;
  const auto out = dir / "out";
  ASSERT_EQ(RunMmh(ShortRun(out)).exit_code, 0);
  const std::string tracked = ReadBytes(out / "takes/take_1/tracked.tum");
  const std::string errors = ReadBytes(out / "tracking_errors.csv");
  // What a run killed between a write and its rename leaves (PID 2^22 + 1: above PID_MAX_LIMIT,
  // Linux's largest PID, so no process runs under it): the resumed run removes it.
  const auto stale = out / "takes/take_1/status.csv.tmp.4194305.7";
  WriteText(stale, "frame,timestamp,sta");
  auto r = RunMmh(ShortRun(out, "--resume --set montage.blend.window=5"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(ReadBytes(out / "takes/take_1/tracked.tum"), tracked);
  EXPECT_EQ(ReadBytes(out / "tracking_errors.csv"), errors);  // from the takes read back
  EXPECT_FALSE(std::filesystem::exists(stale));
  const nlohmann::json run = nlohmann::json::parse(ReadBytes(out / "run.json"));
  EXPECT_EQ(run["seconds"]["rendered_frames"], 0);  // nothing rendered again
  r = RunMmh(ShortRun(out, "--resume --set tracker.verification.max_rms=0.003"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("config.resolved.json: tracker.verification.max_rms"), std::string::npos)
      << r.output;
  std::string status = ReadBytes(out / "takes/take_0/status.csv");
  status.erase(status.rfind('\n', status.size() - 2) + 1);  // drop the last row
  WriteText(out / "takes/take_0/status.csv", status);
  r = RunMmh(ShortRun(out, "--resume"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("take_0/status.csv: got 69 rows, expected 70 frames"), std::string::npos)
      << r.output;
  r = RunMmh(ShortRun(dir / "empty", "--resume"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("config.resolved.json: got missing"), std::string::npos) << r.output;
}

// A baseline made by --update passes; a baseline value moved beyond its tolerance fails (exit 1)
// and the table names the metric.
TEST(RunCliTest, RegressPassesItsOwnBaselineAndCatchesAChange) {
  TempDir dir;
  std::filesystem::create_directories(dir / "baseline");
  WriteText(dir / "baseline/baseline.json",
            R"({"root": ")" + kSource + R"(", "scenarios": [{"name": "quick",
               "config": "configs/soldier.json", "set": ["run.fidelity=fast", "render.frames=300",
               "scenario.story=\"configs/stories/soldier.json\""], "metrics": {}}]})");
  auto r = RunMmh("regress --baseline " + (dir / "baseline").string() + " --update --quiet --out " +
                  (dir / "update").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  nlohmann::json baseline = nlohmann::json::parse(ReadBytes(dir / "baseline/baseline.json"));
  ASSERT_GT(baseline["scenarios"][0]["metrics"].size(), 20u);
  r = RunMmh("regress --baseline " + (dir / "baseline").string() + " --out " +
             (dir / "same").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("0 regressed"), std::string::npos) << r.output;
  baseline["scenarios"][0]["metrics"]["montage.truth.total_cost"]["value"] =
      baseline["scenarios"][0]["metrics"]["montage.truth.total_cost"]["value"].get<double>() * 1.01;
  WriteText(dir / "baseline/baseline.json", baseline.dump(2));
  r = RunMmh("regress --baseline " + (dir / "baseline").string() + " --out " +
             (dir / "moved").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("montage.truth.total_cost"), std::string::npos);
  EXPECT_NE(r.output.find("REGRESSED"), std::string::npos);
  EXPECT_NE(ReadBytes(dir / "moved/regress.csv").find("REGRESSED"), std::string::npos);
}

// The committed short baseline (tests/data/regress): a change in the simulation, the sensor, the
// tracker or the compositor that moves a metric beyond its tolerance fails here.
TEST(RunCliTest, TheCommittedShortBaselinePasses) {
  TempDir dir;
  const auto r = RunMmh("regress --baseline " + kSource + "/tests/data/regress --out " +
                        (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(" 0 regressed or missing"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace mmh
