// Regression against a committed baseline (`mmh regress`): a baseline folder holds baseline.json,
// which names its scenarios (a run config and overrides) and, per scenario, the metrics to check
// with their baseline value, tolerance and which direction is better. Each metric of a new run is
// compared with its baseline: within tolerance it passes; beyond it in the better direction it
// improved (a new baseline may be due); otherwise it regressed.
//
// baseline.json:
//   {"root": "../..",                      folder that relative paths are relative to
//    "scenarios": [{"name": "soldier",
//                   "config": "configs/soldier.json",
//                   "set": ["run.takes=3"],     optional overrides
//                   "config_hash": "...",       of the resolved config the baseline ran
//                   "metrics": {"takes.0.tracking.success_rate":
//                                 {"value": 0.99, "tolerance": 0.02, "relative": false,
//                                  "better": "higher"}, ...}}]}
// "better" is "higher", "lower" or "either" (any change beyond the tolerance is a regression);
// a relative tolerance is a share of |value|.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/animator_run.h"
#include "pipeline/baseline_file.h"

namespace mmh::pipeline {

enum class Verdict { kPass, kImproved, kRegressed, kMissing };
const char* VerdictName(Verdict verdict);

struct MetricComparison {
  std::string scenario;
  std::string metric;
  MetricTolerance baseline;
  double value = 0.0;  // the new run's (NaN when missing)
  Verdict verdict = Verdict::kPass;
};

// Compares a run's metrics.json with a scenario's baseline metrics.
std::vector<MetricComparison> CompareWithBaseline(const Scenario& scenario,
                                                  const nlohmann::json& metrics);

// The metrics a new baseline checks, with the harness's default tolerances (docs/pipeline.md):
// the ground truth (performances, ground-truth montage) almost exactly, the tracker and the
// montage from tracked data within tolerances that absorb small changes.
std::vector<std::pair<std::string, MetricTolerance>> DefaultBaselineMetrics(
    const nlohmann::json& metrics);

nlohmann::json ToJson(const Scenario& scenario);

// A scenario's run config, read and checked before anything runs, and the hash of its resolved
// config with the file paths as the scenario writes them (so that it does not depend on where the
// clone is). Relative file paths of the config (scenario.story, run.practice, render.proxy,
// render.trajectory, render.annotation) resolve against the baseline's root, so that `mmh
// regress` gives the same runs from any working directory.
struct PreparedScenario {
  const Scenario* scenario = nullptr;
  RunConfig config;
  std::string config_hash;
};
PreparedScenario PrepareScenario(const Baseline& baseline, const Scenario& scenario);

// `scenario` with the metrics of a new run (`metrics`: its metrics.json) and the run's config
// hash: the metrics DefaultBaselineMetrics picks, keeping the tolerances a researcher set for
// the metrics the scenario already had.
Scenario UpdatedScenario(const Scenario& scenario, const nlohmann::json& metrics,
                         const std::string& config_hash);

// Rewrites baseline.json (atomically) with `updated` in place of the scenarios of the same name;
// the others are kept as they were, and so is every other key of the file.
void WriteBaseline(const Baseline& baseline, const std::vector<Scenario>& updated);

// A printable table and a tidy CSV of comparisons.
std::string FormatComparisons(const std::vector<MetricComparison>& comparisons);
std::string ComparisonsToCsv(const std::vector<MetricComparison>& comparisons);

}  // namespace mmh::pipeline
