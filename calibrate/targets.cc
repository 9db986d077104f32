#include "calibrate/targets.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>

#include "core/error.h"
#include "core/json_text.h"
#include "core/options.h"
#include "core/text_parsing.h"
#include "study/simulated_study.h"
#include "study/study_analysis.h"

namespace mmh::calibrate {
namespace {

std::vector<std::string> Columns() {
  std::vector<std::string> names;
  for (const auto& s : study::ReplicateStatistics(study::StudyAnalysis{})) names.push_back(s.name);
  return names;
}

void RequireOnlyKeys(const nlohmann::json& object, const std::vector<std::string>& keys,
                     const std::string& where) {
  if (!object.is_object()) ThrowBadValue(where, object.dump().substr(0, 60), "a JSON object");
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) {
      const std::string suggestion = options_internal::SuggestName(it.key(), keys);
      ThrowBadValue(where + "." + it.key(), "an unknown key",
                    suggestion.empty() ? "one of the keys of a target"
                                       : "'" + suggestion + "' (did you mean it?)");
    }
  }
}

std::string RequireString(const nlohmann::json& object, const std::string& key,
                          const std::string& where) {
  if (!object.contains(key) || !object[key].is_string()) {
    ThrowBadValue(where + "." + key, object.contains(key) ? object[key].dump() : "missing",
                  "a string");
  }
  return object[key].get<std::string>();
}

double RequireNumber(const nlohmann::json& object, const std::string& key,
                     const std::string& where) {
  if (!object.contains(key) || !object[key].is_number()) {
    ThrowBadValue(where + "." + key, object.contains(key) ? object[key].dump() : "missing",
                  "a number");
  }
  const double value = object[key].get<double>();
  RequireFinite(value, where + "." + key);
  return value;
}

TargetRole ParseRole(const nlohmann::json& object, const std::string& where) {
  const std::string role = RequireString(object, "role", where);
  if (role == "fit") return TargetRole::kFit;
  if (role == "holdout") return TargetRole::kHoldout;
  ThrowBadValue(where + ".role", "\"" + role + "\"", "\"fit\" or \"holdout\"");
}

std::string RequireColumn(const nlohmann::json& object, const std::string& where,
                          const std::vector<std::string>& columns) {
  const std::string statistic = RequireString(object, "statistic", where);
  if (std::find(columns.begin(), columns.end(), statistic) == columns.end()) {
    const std::string suggestion = options_internal::SuggestName(statistic, columns);
    ThrowBadValue(where + ".statistic", "\"" + statistic + "\"",
                  "a column of replicates.csv" +
                      (suggestion.empty() ? std::string() : " ('" + suggestion + "'?)"));
  }
  return statistic;
}

}  // namespace

const char* RoleName(TargetRole role) { return role == TargetRole::kFit ? "fit" : "holdout"; }

Targets LoadTargets(const std::filesystem::path& file) {
  const std::string source = file.string();
  const nlohmann::json json = ParseJsonText(ReadTextFile(file), source);
  RequireOnlyKeys(json, {"description", "targets", "conclusions"}, source);
  const std::vector<std::string> columns = Columns();
  Targets out;
  out.file = file;
  if (!json.contains("targets") || !json["targets"].is_array() || json["targets"].empty()) {
    ThrowBadValue(source + ": targets", json.contains("targets") ? json["targets"].dump() : "missing",
                  "a non-empty array of {statistic, value, role, quote}");
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < json["targets"].size(); ++i) {
    const nlohmann::json& t = json["targets"][i];
    const std::string where = source + ": targets[" + std::to_string(i) + "]";
    RequireOnlyKeys(t, {"statistic", "value", "role", "quote"}, where);
    Target target;
    target.statistic = RequireColumn(t, where, columns);
    target.value = RequireNumber(t, "value", where);
    target.role = ParseRole(t, where);
    if (t.contains("quote")) target.quote = RequireString(t, "quote", where);
    if (!seen.insert(target.statistic).second) {
      ThrowBadValue(where + ".statistic", "\"" + target.statistic + "\" again",
                    "each statistic once");
    }
    out.targets.push_back(target);
  }
  if (std::none_of(out.targets.begin(), out.targets.end(),
                   [](const Target& t) { return t.role == TargetRole::kFit; })) {
    ThrowBadValue(source + ": targets", "no target with role \"fit\"",
                  "at least one number to calibrate on");
  }
  if (json.contains("conclusions")) {
    if (!json["conclusions"].is_array()) {
      ThrowBadValue(source + ": conclusions", json["conclusions"].dump().substr(0, 60), "an array");
    }
    for (std::size_t i = 0; i < json["conclusions"].size(); ++i) {
      const nlohmann::json& c = json["conclusions"][i];
      const std::string where = source + ": conclusions[" + std::to_string(i) + "]";
      RequireOnlyKeys(c, {"id", "statistic", "bound", "below", "role", "description"}, where);
      Conclusion conclusion;
      conclusion.id = RequireString(c, "id", where);
      conclusion.statistic = RequireColumn(c, where, columns);
      conclusion.bound = RequireNumber(c, "bound", where);
      if (!c.contains("below") || !c["below"].is_boolean()) {
        ThrowBadValue(where + ".below", c.contains("below") ? c["below"].dump() : "missing",
                      "true (the paper found statistic < bound) or false");
      }
      conclusion.below = c["below"].get<bool>();
      conclusion.role = ParseRole(c, where);
      if (c.contains("description")) conclusion.description = RequireString(c, "description", where);
      out.conclusions.push_back(conclusion);
    }
  }
  return out;
}

}  // namespace mmh::calibrate
