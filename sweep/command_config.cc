#include "sweep/command_config.h"

#include <filesystem>
#include <map>
#include <stdexcept>

#include "core/config.h"
#include "core/error.h"
#include "core/options.h"
#include "montage/compose.h"
#include "pipeline/animator_run.h"
#include "study/simulated_study.h"

namespace mmh::sweep {
namespace {

struct InputSpec {
  const char* name;
  bool list;      // one or more values (a JSON list) or one string
  bool required;
  bool file;      // must exist (a file or a folder)
};

std::vector<InputSpec> InputsOf(SweepCommand command) {
  switch (command) {
    case SweepCommand::kCompose:
      return {{"takes", true, true, true}, {"annotations", true, true, true},
              {"markers", true, false, false}};
    case SweepCommand::kTrack:
      return {{"input", false, true, true}, {"model", false, false, true},
              {"setup", false, false, true}};
    case SweepCommand::kStudy:
      return {{"paper-reported", false, false, true}};
    case SweepCommand::kRun:
      return {};
  }
  return {};
}

std::map<SweepCommand, ConfigResolver>& Resolvers() {
  static std::map<SweepCommand, ConfigResolver> resolvers;
  return resolvers;
}

}  // namespace

bool RegisterConfigResolver(SweepCommand command, ConfigResolver resolver) {
  Resolvers()[command] = resolver;
  return true;
}

nlohmann::json ResolveCommandConfig(SweepCommand command, const Config& config) {
  switch (command) {
    case SweepCommand::kCompose:
      // As `mmh compose` reads it (cli/compose_command.cc).
      config.RequireOnlySections({"montage"});
      return {{"montage", ToJson(config.Get<montage::ComposeOptions>("montage"))}};
    case SweepCommand::kRun:
      // As cli/run_command.cc reads it.
      return pipeline::RunConfig::FromConfig(config).ToJson();
    case SweepCommand::kStudy: {
      // As cli/study_command.cc reads it.
      const study::StudyConfig study_config = study::StudyConfig::FromConfig(config);
      study_config.study.Validate("study");
      return study_config.ToJson();
    }
    case SweepCommand::kTrack:
      break;
  }
  const auto it = Resolvers().find(command);
  if (it == Resolvers().end()) {
    throw std::logic_error(std::string("no config resolver for `mmh ") + CommandName(command) +
                           "` in this program (link mmh::sweep_resolvers)");
  }
  return it->second(config);
}

bool NeedsFullFidelity(SweepCommand command, const nlohmann::json& resolved) {
  if (command != SweepCommand::kRun && command != SweepCommand::kStudy) return false;
  const auto run = resolved.find("run");
  if (run == resolved.end() || !run->contains("fidelity")) {
    throw std::logic_error("NeedsFullFidelity: a resolved config without run.fidelity");
  }
  return run->at("fidelity") == EnumName(pipeline::Fidelity::kFull);
}

std::vector<std::string> CommandInputs(const SweepSpec& spec) {
  const std::vector<InputSpec> known = InputsOf(spec.command);
  std::vector<std::string> names;
  for (const auto& k : known) names.emplace_back(k.name);
  const std::string where = spec.file.string() + ": inputs";
  for (auto it = spec.inputs.begin(); it != spec.inputs.end(); ++it) {
    bool found = false;
    for (const auto& k : known) found = found || it.key() == k.name;
    if (found) continue;
    const std::string suggestion = options_internal::SuggestName(it.key(), names);
    throw InputError(where + "." + it.key() + " is not an input of `mmh " +
                     CommandName(spec.command) + "`" +
                     (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)") +
                     "; its inputs: " +
                     (names.empty() ? std::string("none") : options_internal::JoinNames(names)));
  }
  std::vector<std::string> args;
  for (const auto& k : known) {
    const auto it = spec.inputs.find(k.name);
    if (it == spec.inputs.end()) {
      if (k.required) {
        ThrowBadValue(where + "." + k.name, "nothing",
                      std::string(k.list ? "a list of paths" : "a path") + " (required by `mmh " +
                          CommandName(spec.command) + "`)");
      }
      continue;
    }
    std::vector<nlohmann::json> values;
    if (k.list && it->is_array() && !it->empty()) {
      values.assign(it->begin(), it->end());
    } else if (!k.list && (it->is_string())) {
      values.push_back(*it);
    } else {
      ThrowBadValue(where + "." + k.name, it->dump(),
                    k.list ? "a non-empty list" : "a string (a path)");
    }
    args.push_back(std::string("--") + k.name);
    for (const auto& v : values) {
      if (k.file) {
        if (!v.is_string()) ThrowBadValue(where + "." + k.name, v.dump(), "a path (a string)");
        if (!std::filesystem::exists(v.get<std::string>())) {
          ThrowBadValue(where + "." + k.name, v.dump(),
                        "an existing file or folder (paths are relative to the folder mmh sweep "
                        "runs in)");
        }
        args.push_back(v.get<std::string>());
      } else {
        if (!v.is_number_integer()) ThrowBadValue(where + "." + k.name, v.dump(), "an integer");
        args.push_back(v.dump());
      }
    }
  }
  return args;
}

bool PacksByDefault(SweepCommand command) {
  return command == SweepCommand::kCompose;
}

}  // namespace mmh::sweep
