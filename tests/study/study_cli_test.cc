// `mmh study` as a user runs it: the files it writes, `mmh stats` reproducing its numbers from
// them, same bytes on a rerun with another thread count, replicates, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/test_util.h"

namespace mmh {
namespace {

using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;

const std::string kSource = MMH_SOURCE_DIR;

std::string SmallStudy(const std::string& extra = "") {
  return "study --config " + kSource + "/configs/study_soldier.json --set scenario.story=" + kSource +
         "/configs/stories/soldier.json --set run.practice=" + kSource +
         "/configs/stories/mario.json --set run.fidelity=fast --set study.animators=4 --set "
         "render.frames=600 --quiet " +
         extra;
}

// A full-fidelity study renders and tracks every session and fits the error model to what the
// tracker did: DIR/error_model.inc, the file that regenerates fast fidelity's defaults
// (pipeline/error_model.inc, docs/study.md "Fidelity"). Three animators with 61-frame takes (the
// shortest a montage allows) keep it to a few seconds.
TEST(StudyCliTest, FullFidelityWritesTheErrorModelFit) {
  TempDir dir;
  const auto out = dir / "study";
  const auto run = RunMmh("study --config " + kSource + "/configs/study_soldier.json --set " +
                          "scenario.story=" + kSource + "/configs/stories/soldier.json --set " +
                          "run.practice=" + kSource + "/configs/stories/mario.json --set " +
                          "study.animators=3 --set render.frames=61 --quiet --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string fit = ReadBytes(out / "error_model.inc");
  EXPECT_NE(
      fit.find("full-fidelity study of " + kSource + "/configs/study_soldier.json (3 animators"),
      std::string::npos)
      << fit;
  // 3 animators x 3 takes x 61 frames.
  EXPECT_NE(fit.find("// 549 tracked frames"), std::string::npos) << fit;
  const std::string key = "inline constexpr double kTranslationSd = ";
  const auto at = fit.find(key);
  ASSERT_NE(at, std::string::npos) << fit;
  const double translation_sd = std::stod(fit.substr(at + key.size()));
  EXPECT_GT(translation_sd, 1e-4);  // the tracker's jitter, about a millimetre
  EXPECT_LT(translation_sd, 1e-2);
  EXPECT_NE(fit.find("inline constexpr ViewRates kView"), std::string::npos);

  // Every tracked frame is in tracking_errors.csv (and a header), and `mmh error-model` fitted on
  // it gives the study's fit, number for number.
  const std::string frames = ReadBytes(out / "tracking_errors.csv");
  EXPECT_EQ(std::count(frames.begin(), frames.end(), '\n'), 549 + 1);
  const auto refit = RunMmh("error-model --frames " + (out / "tracking_errors.csv").string() +
                            " --quiet --out " + (dir / "refit").string());
  ASSERT_EQ(refit.exit_code, 0) << refit.output;
  const auto results = nlohmann::json::parse(ReadBytes(out / "results.json"));
  EXPECT_EQ(nlohmann::json::parse(ReadBytes(dir / "refit" / "error_model.json")),
            results["measured_error_model"]);
  const std::string refit_inc = ReadBytes(dir / "refit" / "error_model.inc");
  EXPECT_EQ(refit_inc.substr(refit_inc.find("tracked frames")), fit.substr(fit.find("tracked frames")));

  // A damaged table: exit code 2, the file and line named, nothing written.
  test_util::WriteText(dir / "bad.csv", frames.substr(0, frames.find('\n') + 1) + "A01,0,0,x\n");
  const auto bad = RunMmh("error-model --frames " + (dir / "bad.csv").string() + " --out " +
                          (dir / "bad").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("bad.csv:2: 4 fields, expected 18"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad" / "error_model.inc"));
  // A table with its header only: nothing to fit, an error rather than the prior.
  test_util::WriteText(dir / "empty.csv", frames.substr(0, frames.find('\n') + 1));
  const auto empty = RunMmh("error-model --frames " + (dir / "empty.csv").string() + " --out " +
                            (dir / "empty").string());
  EXPECT_EQ(empty.exit_code, 2) << empty.output;
  EXPECT_NE(empty.output.find("empty.csv: no frames after the header"), std::string::npos)
      << empty.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "empty" / "error_model.inc"));
}

TEST(StudyCliTest, WritesEverythingAndStatsReproducesIt) {
  TempDir dir;
  const auto out = dir / "study";
  const auto run = RunMmh(SmallStudy("--threads 1 --out " + out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* file : {"rankings.csv",
                           "comparisons.csv",
                           "segment_costs.csv",
                           "results.json",
                           "tests.csv",
                           "take_scores.csv",
                           "animator_scores.csv",
                           "mean_ranks.csv",
                           "animators.csv",
                           "figure8_mean_ranks.svg",
                           "figure8_mean_ranks.csv",
                           "figure9_take_scores.svg",
                           "figure9_take_scores.csv",
                           "figure10_all_takes.svg",
                           "figure10_all_takes.csv",
                           "figure11_take_order.svg",
                           "figure11_take_order.csv",
                           "paper_comparison.md",
                           "paper_comparison.csv",
                           "report.txt",
                           "config.resolved.json",
                           "run.json"}) {
    EXPECT_TRUE(std::filesystem::exists(out / file)) << file;
  }
  EXPECT_FALSE(std::filesystem::exists(out / "power.csv"));
  // Only a full-fidelity study measures the tracker (FullFidelityWritesTheErrorModelFit).
  EXPECT_FALSE(std::filesystem::exists(out / "error_model.inc"));
  const auto results = nlohmann::json::parse(ReadBytes(out / "results.json"));
  EXPECT_EQ(results["design"]["comparisons"], 4 * 3 * 7);
  EXPECT_EQ(results["design"]["scorers"], 28);

  // `mmh stats` on the study's CSV files gives the same analysis, number for number.
  const auto stats =
      RunMmh("stats --input " + out.string() + " --out " + (dir / "stats").string() + " --quiet");
  ASSERT_EQ(stats.exit_code, 0) << stats.output;
  const auto again = nlohmann::json::parse(ReadBytes(dir / "stats" / "results.json"));
  EXPECT_EQ(again, results["analysis"]);
  EXPECT_EQ(ReadBytes(dir / "stats" / "tests.csv"), ReadBytes(out / "tests.csv"));

  // Same bytes with all cores; the resolved config reruns to the same results.
  const auto rerun = RunMmh(SmallStudy("--out " + (dir / "again").string()));
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  for (const char* file : {"results.json", "comparisons.csv", "rankings.csv", "animators.csv",
                           "figure9_take_scores.svg", "paper_comparison.md"}) {
    EXPECT_EQ(ReadBytes(out / file), ReadBytes(dir / "again" / file)) << file;
  }
}

TEST(StudyCliTest, ReplicatesReportPower) {
  TempDir dir;
  const auto out = dir / "power";
  const auto run =
      RunMmh(SmallStudy("--replicates 2 --set study.animators=3 --out " + out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string replicates = ReadBytes(out / "replicates.csv");
  EXPECT_EQ(std::count(replicates.begin(), replicates.end(), '\n'), 3);
  const auto results = nlohmann::json::parse(ReadBytes(out / "results.json"));
  ASSERT_TRUE(results.contains("power"));
  for (const auto& p : results["power"]) {
    EXPECT_LE(p["significant"].get<int>(), p["replicates"].get<int>());
    EXPECT_LE(p["replicates"].get<int>(), 2);
  }
}

TEST(StudyCliTest, BadInputExitsTwoAndWritesNothing) {
  TempDir dir;
  for (const std::string& bad :
       {std::string("--set study.animatorz=4"), std::string("--set study.animators=2"),
        std::string("--set scorers.count=5"), std::string("--set viewer.smoothing=4"),
        std::string("--paper-reported ") + (dir / "missing.json").string()}) {
    const auto out = dir / "out";
    const auto run = RunMmh(SmallStudy(bad + " --out " + out.string()));
    EXPECT_EQ(run.exit_code, 2) << bad << "\n" << run.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << bad;
  }
}

}  // namespace
}  // namespace mmh
