// What is performed and by whom: the scenario of a run (paper, "Study Design": each participant
// records takes of one object of a story, then annotates them), and every config section of the
// simulated people in one place. `mmh render`, `mmh run`, `mmh study` and `mmh regress` read the
// people from here and the sensor and scene from sim::RenderConfig, so that neither rides inside
// the other.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "core/config.h"
#include "people/annotator.h"
#include "people/performance.h"
#include "people/population.h"

namespace mmh::people {

// Config section "scenario".
struct ScenarioOptions {
  // The story (configs/stories/*.json). Empty: no story (`mmh render` then plays a trajectory
  // file or its demo walk; `mmh run` and `mmh study` need one).
  std::string story;
  // The story's object whose takes are performed (0-based).
  int object = 0;
  // The participant of the population (section "population") who performs them (0-based).
  // `mmh study` runs participants 0 .. study.animators - 1 and leaves this at 0.
  int animator = 0;

  template <class V>
  void VisitFields(V& v) {
    v("story", story);
    v("object", object);
    v("animator", animator);
  }
  void Validate(const std::string& prefix) const;
};

// The people's sections of a config: "scenario", "population", "performance", "annotator".
struct PeopleConfig {
  ScenarioOptions scenario;
  PopulationOptions population;
  PerformanceOptions performance;
  AnnotatorOptions annotator;

  // Reads the four sections (other sections are left to the callers). The scenario's keys were
  // render.story, render.animator and render.object before 2026-11: a config that still has
  // them gets an InputError saying where they went.
  static PeopleConfig FromConfig(const Config& config);
  // Adds the four sections to `json` (a resolved config).
  void AddToJson(nlohmann::json& json) const;
};

}  // namespace mmh::people
