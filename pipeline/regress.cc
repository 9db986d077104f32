#include "pipeline/regress.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

#include "core/atomic_file.h"
#include "core/config.h"
#include "core/config_hash.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "core/options.h"
#include "pipeline/run_metrics.h"

namespace mmh::pipeline {

namespace {

const char* BetterName(Better better) { return EnumName(better); }

}  // namespace

const char* VerdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPass:
      return "pass";
    case Verdict::kImproved:
      return "improved";
    case Verdict::kRegressed:
      return "REGRESSED";
    case Verdict::kMissing:
      return "MISSING";
  }
  return "?";
}

std::vector<MetricComparison> CompareWithBaseline(const Scenario& scenario,
                                                  const nlohmann::json& metrics) {
  std::map<std::string, double> values;
  for (const auto& [key, value] : FlattenMetrics(metrics)) values[key] = value;
  std::vector<MetricComparison> out;
  for (const auto& [key, t] : scenario.metrics) {
    MetricComparison c;
    c.scenario = scenario.name;
    c.metric = key;
    c.baseline = t;
    const auto it = values.find(key);
    if (it == values.end()) {
      c.value = std::numeric_limits<double>::quiet_NaN();
      c.verdict = Verdict::kMissing;
      out.push_back(c);
      continue;
    }
    c.value = it->second;
    const double allowed = t.relative ? t.tolerance * std::abs(t.value) : t.tolerance;
    const double change = c.value - t.value;
    // A little slack for the decimal round trip of the baseline file.
    if (std::abs(change) <= allowed + 1e-12 * std::max(1.0, std::abs(t.value))) {
      c.verdict = Verdict::kPass;
    } else if ((t.better == Better::kHigher && change > 0) ||
               (t.better == Better::kLower && change < 0)) {
      c.verdict = Verdict::kImproved;
    } else {
      c.verdict = Verdict::kRegressed;
    }
    out.push_back(c);
  }
  return out;
}

std::vector<std::pair<std::string, MetricTolerance>> DefaultBaselineMetrics(
    const nlohmann::json& metrics) {
  std::map<std::string, double> values;
  for (const auto& [key, value] : FlattenMetrics(metrics)) values[key] = value;
  std::vector<std::pair<std::string, MetricTolerance>> out;
  auto add = [&](const std::string& key, double tolerance, bool relative, Better better) {
    const auto it = values.find(key);
    if (it == values.end()) return;
    out.emplace_back(key, MetricTolerance{it->second, tolerance, relative, better});
  };
  // The ground truth (performance, annotator, compositor on true data): exact up to rounding.
  // The tracker and the slider reader: small changes pass, and so does the montage built on them.
  for (size_t k = 0; k < metrics["takes"].size(); ++k) {
    const std::string p = "takes." + std::to_string(k) + ".";
    add(p + "frames", 0, false, Better::kEither);
    add(p + "mean_quality", 1e-9, true, Better::kEither);
    add(p + "tracking.success_rate", 0.02, false, Better::kHigher);
    add(p + "tracking.rotation_deg.median", 0.25, false, Better::kLower);
    add(p + "tracking.translation_m.median", 0.0005, false, Better::kLower);
    add(p + "tracking.longest_failure_frames", 5, false, Better::kLower);
    add(p + "tracking.ape_translation_m.rmse", 0.002, false, Better::kLower);
    add(p + "annotation.rmse", 0.05, false, Better::kLower);
  }
  add("practice.tracking.success_rate", 0.02, false, Better::kHigher);
  add("tracking.success_rate", 0.01, false, Better::kHigher);
  add("annotation.rmse", 0.03, false, Better::kLower);
  add("montage.truth.total_cost", 1e-9, true, Better::kEither);
  add("montage.truth.segments", 0, false, Better::kEither);
  add("montage.truth.mean_quality", 1e-9, true, Better::kEither);
  add("montage.tracked.total_cost", 0.05, true, Better::kEither);
  add("montage.tracked.segments", 2, false, Better::kEither);
  add("montage.tracked.mean_quality", 0.02, false, Better::kHigher);
  add("montage.tracked.constraint_increase_percent", 1.0, false, Better::kLower);
  add("montage.tracked_vs_truth.label_agreement", 0.05, false, Better::kHigher);
  return out;
}

nlohmann::json ToJson(const Scenario& scenario) {
  nlohmann::json j;
  j["name"] = scenario.name;
  j["config"] = scenario.config.string();
  j["set"] = scenario.sets;
  j["config_hash"] = scenario.config_hash;
  nlohmann::json metrics = nlohmann::json::object();
  for (const auto& [key, t] : scenario.metrics) {
    metrics[key] = {{"value", t.value},
                    {"tolerance", t.tolerance},
                    {"relative", t.relative},
                    {"better", BetterName(t.better)}};
  }
  j["metrics"] = metrics;
  return j;
}

std::string FormatComparisons(const std::vector<MetricComparison>& comparisons) {
  size_t width = 6;
  for (const MetricComparison& c : comparisons) width = std::max(width, c.metric.size());
  std::ostringstream out;
  out << std::left << std::setw(10) << "scenario" << ' ' << std::setw(width) << "metric"
      << std::right << std::setw(14) << "baseline" << std::setw(14) << "now" << std::setw(12)
      << "tolerance"
      << "  better  verdict\n";
  for (const MetricComparison& c : comparisons) {
    std::ostringstream tolerance;
    tolerance << (c.baseline.relative ? "" : "±") << std::setprecision(3) << c.baseline.tolerance
              << (c.baseline.relative ? " rel" : "");
    out << std::left << std::setw(10) << c.scenario << ' ' << std::setw(width) << c.metric
        << std::right << std::setw(14) << std::setprecision(6) << c.baseline.value << std::setw(14)
        << c.value << std::setw(12) << tolerance.str() << "  " << std::left << std::setw(8)
        << BetterName(c.baseline.better) << VerdictName(c.verdict) << '\n';
  }
  return out.str();
}

std::string ComparisonsToCsv(const std::vector<MetricComparison>& comparisons) {
  std::ostringstream out;
  out << "scenario,metric,baseline,value,tolerance,relative,better,verdict\n";
  for (const MetricComparison& c : comparisons) {
    out << c.scenario << ',' << c.metric << ',' << FormatNumber(c.baseline.value) << ','
        << (std::isnan(c.value) ? "" : FormatNumber(c.value)) << ','
        << FormatNumber(c.baseline.tolerance) << ',' << (c.baseline.relative ? "true" : "false")
        << ',' << BetterName(c.baseline.better) << ',' << VerdictName(c.verdict) << '\n';
  }
  return out.str();
}

namespace {

// The config keys that name files.
constexpr const char* kPathKeys[][2] = {{"scenario", "story"},
                                        {"run", "practice"},
                                        {"render", "proxy"},
                                        {"render", "trajectory"},
                                        {"render", "annotation"}};

}  // namespace

PreparedScenario PrepareScenario(const Baseline& baseline, const Scenario& scenario) {
  Config config = Config::Load(scenario.config);
  for (const std::string& set : scenario.sets) config.Set(set);
  const nlohmann::json as_written = config.root();
  for (const auto& [section, key] : kPathKeys) {
    const auto s = config.root().find(section);
    if (s == config.root().end() || !s->is_object()) continue;
    const auto v = s->find(key);
    if (v == s->end() || !v->is_string()) continue;
    const std::string path = v->get<std::string>();
    if (path.empty() || std::filesystem::path(path).is_absolute()) continue;
    config.Set(std::string(section) + "." + key + "=" +
               nlohmann::json((baseline.root / path).lexically_normal().string()).dump());
  }
  PreparedScenario prepared{&scenario, RunConfig::FromConfig(config), ""};
  nlohmann::json resolved = prepared.config.ToJson();
  for (const auto& [section, key] : kPathKeys) {
    if (as_written.contains(section) && as_written[section].contains(key)) {
      resolved[section][key] = as_written[section][key];
    }
  }
  prepared.config_hash = ConfigHash(resolved);
  return prepared;
}

Scenario UpdatedScenario(const Scenario& scenario, const nlohmann::json& metrics,
                         const std::string& config_hash) {
  Scenario next = scenario;
  next.config_hash = config_hash;
  next.metrics = DefaultBaselineMetrics(metrics);
  for (auto& [key, t] : next.metrics) {
    for (const auto& [old_key, old] : scenario.metrics) {
      if (old_key == key) t.tolerance = old.tolerance, t.relative = old.relative, t.better = old.better;
    }
  }
  return next;
}

void WriteBaseline(const Baseline& baseline, const std::vector<Scenario>& updated) {
  nlohmann::json scenarios = nlohmann::json::array();
  for (const Scenario& s : baseline.scenarios) {
    const auto u = std::find_if(updated.begin(), updated.end(),
                                [&](const Scenario& u) { return u.name == s.name; });
    nlohmann::json j = ToJson(u == updated.end() ? s : *u);
    j["config"] = std::filesystem::relative(s.config, baseline.root).string();
    scenarios.push_back(j);
  }
  nlohmann::json file = ReadJsonFile(baseline.file);
  file["scenarios"] = scenarios;
  WriteFileAtomically(baseline.file, file.dump(2) + "\n");
}

}  // namespace mmh::pipeline
