// The baseline file of `mmh regress` (baseline.json; its format: pipeline/regress.h): the types
// and the reader, on their own so that the reader needs only core (the clang fuzz build compiles
// it into fuzz/baseline_fuzzer.cc without the pipeline, simulator and tracker).
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace mmh::pipeline {

enum class Better { kHigher, kLower, kEither };
std::span<const std::pair<Better, const char*>> EnumNames(Better);

// One metric's baseline entry (read through core/options.h: unknown keys are errors).
struct MetricTolerance {
  double value = 0.0;
  double tolerance = 0.0;  // >= 0; absolute, or a share of |value| when relative
  bool relative = false;
  Better better = Better::kEither;

  template <class V>
  void VisitFields(V& v) {
    v("value", value);
    v("tolerance", tolerance);
    v("relative", relative);
    v("better", better);
  }
  void Validate(const std::string& prefix) const;
};

struct Scenario {
  std::string name;
  std::filesystem::path config;  // resolved against the baseline's root
  std::vector<std::string> sets;
  std::string config_hash;
  std::vector<std::pair<std::string, MetricTolerance>> metrics;
};

struct Baseline {
  std::filesystem::path file;  // baseline.json
  std::filesystem::path root;  // relative paths in scenarios and their configs resolve here
  std::vector<Scenario> scenarios;
};

// Reads `folder`/baseline.json (InputError naming the file and key for anything malformed).
Baseline ReadBaseline(const std::filesystem::path& folder);

}  // namespace mmh::pipeline
