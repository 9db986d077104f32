// `mmh calibrate` end to end on a small real sweep of fast studies: the outputs, determinism, and
// clear errors for a folder that is not a calibration sweep.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test_util::ReadBytes;
using test_util::RunMmh;

class CalibrateCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The study config's story paths are relative to the project (as when run from it).
    fs::current_path(MMH_SOURCE_DIR);
    // Four cells of one parameter, 2 studies of 5 animators each (about 0.2 s of CPU a study).
    json spec = {
        {"command", "study"},
        {"config", std::string(MMH_SOURCE_DIR) + "/configs/study_soldier.json"},
        {"set",
         {"run.fidelity=\"fast\"", "run.metrics=false", "study.replicates=2", "study.animators=5"}},
        {"samples",
         {{"method", "latin_hypercube"},
          {"count", 4},
          {"seed", 7},
          {"axes", {{{"key", "viewer.judgement_noise"}, {"from", 0.02}, {"to", 0.4}}}}}},
        {"metrics", {{{"name", "h1_mean_m"}, {"file", "results.json"}, {"key", "analysis.h1.mean_m"}}}}};
    spec_ = temp_ / "spec.json";
    test_util::WriteText(spec_, spec.dump(2));
    targets_ = temp_ / "targets.json";
    test_util::WriteText(targets_, R"({"targets": [
      {"statistic": "h1_mean_m", "value": 0.65, "role": "fit"},
      {"statistic": "h3_f", "value": 0.83, "role": "holdout"}],
      "conclusions": [{"id": "h3", "statistic": "p_h3_mixed_model", "bound": 0.05,
                       "below": false, "role": "holdout"}]})");
  }
  void RunSweep() {
    const auto sweep = RunMmh("sweep --quiet --jobs 2 --spec " + spec_.string() + " --out " +
                              (temp_ / "sweep").string());
    ASSERT_EQ(sweep.exit_code, 0) << sweep.output;
  }
  test_util::CommandResult Calibrate(const fs::path& out) {
    return RunMmh("calibrate --quiet --sweep " + (temp_ / "sweep").string() + " --targets " +
                  targets_.string() + " --set calibration.ppc_replicates=4 --set " +
                  "calibration.abc.accept_fraction=0.5 --out " + out.string());
  }
  test_util::TempDir temp_;
  fs::path spec_, targets_;
};

TEST_F(CalibrateCliTest, FitsChecksAndReproducesItsBytes) {
  RunSweep();
  const auto r = Calibrate(temp_ / "a");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json c = json::parse(ReadBytes(temp_ / "a" / "calibration.json"));
  EXPECT_EQ(c["cells"], 4);
  EXPECT_EQ(c["simulations"], 8);
  EXPECT_EQ(c["accepted"], 4);
  const double estimate = c["parameters"][0]["estimate"];
  EXPECT_GE(estimate, 0.02);
  EXPECT_LE(estimate, 0.4);
  EXPECT_EQ(c["targets"][1]["role"], "holdout");
  EXPECT_EQ(c["targets"][1]["ppc"]["samples"], 4);
  EXPECT_EQ(c["conclusions"][0]["replicates"], 4);
  // The calibrated value is a config fragment the study accepts.
  const json calibrated = json::parse(ReadBytes(temp_ / "a" / "calibrated.json"));
  EXPECT_TRUE(calibrated["viewer"]["judgement_noise"].is_number());
  for (const char* f : {"report.md", "parameters.csv", "posterior.csv", "identification.csv",
                        "targets.csv", "conclusions.csv", "ppc_replicates.csv",
                        "config.resolved.json", "run.json"}) {
    EXPECT_TRUE(fs::exists(temp_ / "a" / f)) << f;
  }
  // Same sweep and options: the same bytes (all but run.json's provenance).
  ASSERT_EQ(Calibrate(temp_ / "b").exit_code, 0);
  for (const auto& entry : fs::directory_iterator(temp_ / "a")) {
    const std::string name = entry.path().filename().string();
    if (name == "run.json") continue;
    EXPECT_EQ(ReadBytes(entry.path()), ReadBytes(temp_ / "b" / name)) << name;
  }
}

TEST_F(CalibrateCliTest, NotACalibrationSweepIsAClearError) {
  const auto r = RunMmh("calibrate --sweep " + temp_.path().string() + " --out " +
                        (temp_ / "c").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("plan.json"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(temp_ / "c"));
  const auto t = RunMmh("calibrate --sweep " + temp_.path().string() + " --targets " +
                        (temp_ / "missing.json").string() + " --out " + (temp_ / "c").string());
  EXPECT_EQ(t.exit_code, 2) << t.output;
  EXPECT_NE(t.output.find("missing.json"), std::string::npos) << t.output;
  EXPECT_FALSE(fs::exists(temp_ / "c"));
}

}  // namespace
}  // namespace mmh
