// `mmh calibrate` end to end on a small real sweep of fast studies: the outputs, determinism, and
// clear errors for a folder that is not a calibration sweep.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>
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
  test_util::CommandResult Calibrate(const fs::path& out, const std::string& extra = "") {
    return RunMmh("calibrate --quiet --sweep " + (temp_ / "sweep").string() + " --targets " +
                  targets_.string() + " --set calibration.ppc_replicates=4 --set " +
                  "calibration.abc.accept_fraction=0.5 " + extra + " --out " + out.string());
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
  for (const char* f : {"report.md", "parameters.csv", "stability.csv", "next_round.json",
                        "posterior.csv", "identification.csv",
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

// Reads a CSV with a header into rows of fields.
std::vector<std::vector<std::string>> ReadCsv(const fs::path& file) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(ReadBytes(file));
  std::string line;
  while (std::getline(lines, line)) {
    std::vector<std::string> fields;
    std::istringstream f(line);
    std::string field;
    while (std::getline(f, field, ',')) fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

// The predictive studies' parameters: the accepted, adjusted θ in order (posterior draws, cycling)
// or the rounded estimate; next_round.json is a sweep spec over the accepted region that mmh sweep
// plans.
TEST_F(CalibrateCliTest, PredictiveDrawsAndTheNextRound) {
  RunSweep();
  ASSERT_EQ(Calibrate(temp_ / "p", "--set calibration.ppc_replicates=6 "
                                   "--set calibration.next_round.replicates=3 "
                                   "--set calibration.next_round.points=5").exit_code, 0);
  const auto posterior = ReadCsv(temp_ / "p" / "posterior.csv");  // header + 4 accepted
  const auto ppc = ReadCsv(temp_ / "p" / "ppc_replicates.csv");    // header + 6 studies
  ASSERT_EQ(posterior.size(), 5u);
  ASSERT_EQ(ppc.size(), 7u);
  EXPECT_EQ(posterior[0][3], "viewer.judgement_noise.adjusted");
  EXPECT_EQ(ppc[0][1], "viewer.judgement_noise");
  for (int r = 0; r < 6; ++r) {
    EXPECT_EQ(ppc[r + 1][1], posterior[1 + r % 4][3]) << "study " << r;
  }
  const json c = json::parse(ReadBytes(temp_ / "p" / "calibration.json"));
  EXPECT_EQ(c["ppc_draws"], "posterior");

  // The next round's box holds every accepted θ and lies inside the prior; mmh sweep plans it.
  const json next = json::parse(ReadBytes(temp_ / "p" / "next_round.json"));
  const double from = next["samples"]["axes"][0]["from"], to = next["samples"]["axes"][0]["to"];
  EXPECT_GE(from, 0.02);
  EXPECT_LE(to, 0.4);
  for (int r = 1; r <= 4; ++r) {
    const double theta = std::stod(posterior[r][3]);
    EXPECT_GE(theta, from);
    EXPECT_LE(theta, to);
  }
  EXPECT_EQ(next["samples"]["count"], 5);
  EXPECT_EQ(next["samples"]["seed"], 8);
  EXPECT_EQ(next["set"].back(), "study.replicates=3");
  EXPECT_EQ(std::count(next["set"].begin(), next["set"].end(), json("study.replicates=2")), 0);
  const auto plan = RunMmh("sweep --quiet --dry-run --spec " + (temp_ / "p" / "next_round.json").string() +
                           " --out " + (temp_ / "round2").string());
  EXPECT_EQ(plan.exit_code, 0) << plan.output;

  // At the estimate: every study at calibrated.json's value.
  ASSERT_EQ(Calibrate(temp_ / "e", "--set calibration.ppc_draws=estimate").exit_code, 0);
  const json calibrated = json::parse(ReadBytes(temp_ / "e" / "calibrated.json"));
  const auto at_estimate = ReadCsv(temp_ / "e" / "ppc_replicates.csv");
  ASSERT_EQ(at_estimate.size(), 5u);
  for (std::size_t r = 1; r < at_estimate.size(); ++r) {
    EXPECT_DOUBLE_EQ(std::stod(at_estimate[r][1]),
                     calibrated["viewer"]["judgement_noise"].get<double>());
  }
  const auto bad = Calibrate(temp_ / "x", "--set calibration.next_round.margin=-1");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("calibration.next_round.margin"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(temp_ / "x"));
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
