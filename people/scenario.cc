#include "people/scenario.h"

#include "core/error.h"

namespace mmh::people {
namespace {

// The keys that moved from "render" to "scenario".
void RefuseOldScenarioKeys(const Config& config) {
  const auto render = config.root().find("render");
  if (render == config.root().end() || !render->is_object()) return;
  for (const char* key : {"story", "animator", "object"}) {
    if (render->contains(key)) {
      const std::string old_key = std::string("render.") + key;
      throw InputError(config.SourceOf(old_key).name + ": key '" + old_key +
                       "' has moved to 'scenario." + key + "' (the section \"scenario\" says what "
                       "is performed and by whom; \"render\" only how it is rendered)");
    }
  }
}

}  // namespace

void ScenarioOptions::Validate(const std::string& prefix) const {
  if (!story.empty() && !story.ends_with(".json")) {
    ThrowBadValue(prefix + ".story", "\"" + story + "\"", "a story file (.json), or empty");
  }
  for (const auto& [value, name] : {std::pair{object, "object"}, {animator, "animator"}}) {
    if (value < 0 || value > 100000) {
      ThrowBadValue(prefix + "." + name, std::to_string(value), "an index in [0, 100000]");
    }
  }
}

PeopleConfig PeopleConfig::FromConfig(const Config& config) {
  RefuseOldScenarioKeys(config);
  PeopleConfig c;
  c.scenario = config.Get<ScenarioOptions>("scenario");
  c.population = config.Get<PopulationOptions>("population");
  c.performance = config.Get<PerformanceOptions>("performance");
  c.annotator = config.Get<AnnotatorOptions>("annotator");
  return c;
}

void PeopleConfig::AddToJson(nlohmann::json& json) const {
  json["scenario"] = mmh::ToJson(scenario);
  json["population"] = mmh::ToJson(population);
  json["performance"] = mmh::ToJson(performance);
  json["annotator"] = mmh::ToJson(annotator);
}

}  // namespace mmh::people
