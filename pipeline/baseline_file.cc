#include "pipeline/baseline_file.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_text.h"
#include "core/options.h"

namespace mmh::pipeline {

namespace {

constexpr std::pair<Better, const char*> kBetterNames[] = {
    {Better::kHigher, "higher"}, {Better::kLower, "lower"}, {Better::kEither, "either"}};

const nlohmann::json& Require(const nlohmann::json& object, const std::string& key,
                              const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) ThrowBadValue(where + "." + key, "nothing", "a value (missing key)");
  return *it;
}

void RequireOnlyKeys(const nlohmann::json& object, const std::vector<std::string>& keys,
                     const std::string& where) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      std::string expected;
      for (const std::string& k : keys) expected += (expected.empty() ? "" : ", ") + k;
      ThrowBadValue(where + "." + key, "an unknown key", "one of " + expected);
    }
  }
}

}  // namespace

std::span<const std::pair<Better, const char*>> EnumNames(Better) { return kBetterNames; }

void MetricTolerance::Validate(const std::string& prefix) const {
  RequireFinite(value, prefix + ".value");
  RequireNonNegative(tolerance, prefix + ".tolerance");
}

Baseline ReadBaseline(const std::filesystem::path& folder) {
  Baseline b;
  b.file = folder / "baseline.json";
  const nlohmann::json j = ReadJsonFile(b.file);
  const std::string file = b.file.string();
  if (!j.is_object()) ThrowBadValue(file, j.dump().substr(0, 40), "a JSON object");
  RequireOnlyKeys(j, {"root", "scenarios", "comment"}, file);
  const nlohmann::json& root = Require(j, "root", file);
  if (!root.is_string()) ThrowBadValue(file + ": root", root.dump(), "a folder path");
  b.root = (folder / root.get<std::string>()).lexically_normal();
  const nlohmann::json& scenarios = Require(j, "scenarios", file);
  if (!scenarios.is_array() || scenarios.empty()) {
    ThrowBadValue(file + ": scenarios", scenarios.dump().substr(0, 40), "a non-empty array");
  }
  for (size_t i = 0; i < scenarios.size(); ++i) {
    const std::string where = file + ": scenarios[" + std::to_string(i) + "]";
    const nlohmann::json& s = scenarios[i];
    if (!s.is_object()) ThrowBadValue(where, s.dump().substr(0, 40), "an object");
    RequireOnlyKeys(s, {"name", "config", "set", "config_hash", "metrics"}, where);
    Scenario scenario;
    const nlohmann::json& name = Require(s, "name", where);
    const nlohmann::json& config = Require(s, "config", where);
    if (!name.is_string() || name.get<std::string>().empty()) {
      ThrowBadValue(where + ".name", name.dump(), "a non-empty name");
    }
    if (!config.is_string()) ThrowBadValue(where + ".config", config.dump(), "a config path");
    scenario.name = name.get<std::string>();
    scenario.config = b.root / config.get<std::string>();
    if (s.contains("set")) {
      if (!s["set"].is_array()) ThrowBadValue(where + ".set", s["set"].dump(), "an array");
      for (const nlohmann::json& set : s["set"]) {
        if (!set.is_string()) ThrowBadValue(where + ".set", set.dump(), "key.path=value strings");
        scenario.sets.push_back(set.get<std::string>());
      }
    }
    if (s.contains("config_hash")) {
      if (!s["config_hash"].is_string()) {
        ThrowBadValue(where + ".config_hash", s["config_hash"].dump(), "a hash string");
      }
      scenario.config_hash = s["config_hash"].get<std::string>();
    }
    const nlohmann::json& metrics = Require(s, "metrics", where);
    // Empty for a new scenario: `mmh regress --update` fills it in.
    if (!metrics.is_object()) {
      ThrowBadValue(where + ".metrics", metrics.dump().substr(0, 40), "an object");
    }
    for (const auto& [key, m] : metrics.items()) {
      MetricTolerance t;
      FromJson(m, "scenarios[" + std::to_string(i) + "].metrics." + key, ConfigSource{file}, &t);
      t.Validate(where + ".metrics." + key);
      scenario.metrics.emplace_back(key, t);
    }
    for (const Scenario& other : b.scenarios) {
      if (other.name == scenario.name) {
        ThrowBadValue(where + ".name", "\"" + scenario.name + "\"", "a name not used before");
      }
    }
    b.scenarios.push_back(std::move(scenario));
  }
  return b;
}

}  // namespace mmh::pipeline
