// What the calibration aims at (configs/calibration/paper_targets.json): the paper's reported
// numbers, each the value of one column of a study's replicates.csv (study/simulated_study.h
// ReplicateStatistics), used either to fit the people's parameters or held out to validate them;
// and the conclusions the paper drew, checked in the posterior predictive replicates.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mmh::calibrate {

enum class TargetRole { kFit, kHoldout };

struct Target {
  std::string statistic;  // a replicates.csv column, e.g. "h1_mean_m"
  double value = 0.0;     // the paper's number
  TargetRole role = TargetRole::kFit;
  std::string quote;  // where the paper says it
};

// A conclusion of the paper: a test significant (or not) at the study's alpha, or a statistic
// below a bound ("less than 1 % in all the 10 cases").
struct Conclusion {
  std::string id;         // e.g. "friedman"
  std::string statistic;  // a replicates.csv column: "p_friedman", "max_paper_scale_percent"
  double bound = 0.05;    // the conclusion holds when (statistic < bound) == below
  bool below = true;
  TargetRole role = TargetRole::kFit;  // held out when its statistic was not fitted
  std::string description;
};

struct Targets {
  std::filesystem::path file;
  std::vector<Target> targets;
  std::vector<Conclusion> conclusions;
};

// Reads and checks a targets file: unknown keys, a role other than "fit" / "holdout", a statistic
// that is not a replicates.csv column, no fit target: InputErrors naming the file and the entry.
Targets LoadTargets(const std::filesystem::path& file);

const char* RoleName(TargetRole role);

}  // namespace mmh::calibrate
