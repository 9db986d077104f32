// `mmh regress`: runs the scenarios of a baseline (pipeline/regress.h) and compares every metric
// with its tolerance; exit code 1 on a regression. `--update` writes a new baseline instead.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "cli/run_command.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "pipeline/animator_run.h"
#include "pipeline/regress.h"
#include "pipeline/run_metrics.h"

namespace mmh::cli {
namespace {

struct RegressArgs {
  CommonFlags common;
  std::string baseline;
  std::vector<std::string> scenarios;
  bool update = false;
};

// The config keys that name files.
constexpr const char* kPathKeys[][2] = {{"render", "story"},
                                        {"run", "practice"},
                                        {"render", "proxy"},
                                        {"render", "trajectory"},
                                        {"render", "annotation"}};

// Relative file paths of a scenario's config resolve against the baseline's root, so that
// `mmh regress` gives the same runs from any working directory. Returns the config's JSON with
// the paths as written (for the config hash, which must not depend on where the clone is).
nlohmann::json ResolvePaths(Config& config, const std::filesystem::path& root) {
  const nlohmann::json as_written = config.root();
  for (const auto& [section, key] : kPathKeys) {
    const auto s = config.root().find(section);
    if (s == config.root().end() || !s->is_object()) continue;
    const auto v = s->find(key);
    if (v == s->end() || !v->is_string()) continue;
    const std::string path = v->get<std::string>();
    if (path.empty() || std::filesystem::path(path).is_absolute()) continue;
    config.Set(std::string(section) + "." + key + "=" +
               nlohmann::json((root / path).lexically_normal().string()).dump());
  }
  return as_written;
}

void RunRegress(const RegressArgs& args, const std::vector<std::string>& argv) {
  const pipeline::Baseline baseline = pipeline::ReadBaseline(args.baseline);
  for (const std::string& name : args.scenarios) {
    const bool known = std::any_of(baseline.scenarios.begin(), baseline.scenarios.end(),
                                   [&](const pipeline::Scenario& s) { return s.name == name; });
    if (!known) {
      std::string names;
      for (const auto& s : baseline.scenarios) names += (names.empty() ? "" : ", ") + s.name;
      ThrowBadValue("--scenario", "\"" + name + "\"",
                    "a scenario of " + baseline.file.string() + " (" + names + ")");
    }
  }
  // Every scenario's config is read and checked before anything runs.
  struct Prepared {
    const pipeline::Scenario* scenario;
    pipeline::RunConfig config;
    std::string hash;
  };
  std::vector<Prepared> runs;
  for (const pipeline::Scenario& scenario : baseline.scenarios) {
    if (!args.scenarios.empty() && std::find(args.scenarios.begin(), args.scenarios.end(),
                                             scenario.name) == args.scenarios.end()) {
      continue;
    }
    Config config = Config::Load(scenario.config);
    for (const std::string& set : scenario.sets) config.Set(set);
    const nlohmann::json as_written = ResolvePaths(config, baseline.root);
    pipeline::RunConfig run_config = pipeline::RunConfig::FromConfig(config);
    // The hash of the resolved config with the paths as the scenario writes them.
    nlohmann::json resolved = run_config.ToJson();
    for (const auto& [section, key] : kPathKeys) {
      if (as_written.contains(section) && as_written[section].contains(key)) {
        resolved[section][key] = as_written[section][key];
      }
    }
    const std::string hash = ConfigHash(resolved);
    runs.push_back({&scenario, std::move(run_config), hash});
  }
  const auto threads = LimitThreads(args.common.threads);
  const std::filesystem::path out = args.common.out_dir;
  EnsureDirectory(out);
  const bool bar = ShowProgress(args.common);
  std::vector<pipeline::MetricComparison> comparisons;
  nlohmann::json updated = nlohmann::json::array();
  nlohmann::json report = nlohmann::json::array();
  for (const Prepared& p : runs) {
    if (!args.common.quiet && !p.scenario->config_hash.empty() &&
        p.scenario->config_hash != p.hash) {
      std::cerr << "regress: " << p.scenario->name << ": the resolved config differs from the "
                << "baseline's (hash " << p.hash << ", baseline " << p.scenario->config_hash
                << "): a default changed; differences may come from that\n";
    }
    const pipeline::AnimatorRun run =
        RunScenario(p.config, p.config.render.render.animator, out / p.scenario->name, bar, argv,
                    args.common.threads);
    const auto c = pipeline::CompareWithBaseline(*p.scenario, run.metrics);
    comparisons.insert(comparisons.end(), c.begin(), c.end());
    report.push_back({{"scenario", p.scenario->name},
                      {"config_hash", p.hash},
                      {"seconds", pipeline::SecondsToJson(run)}});
    if (args.update) {
      pipeline::Scenario next = *p.scenario;
      next.config_hash = p.hash;
      // Keep the tolerances a researcher set; new metrics get the defaults.
      auto defaults = pipeline::DefaultBaselineMetrics(run.metrics);
      for (auto& [key, t] : defaults) {
        for (const auto& [old_key, old] : p.scenario->metrics) {
          if (old_key == key) {
            t.tolerance = old.tolerance, t.relative = old.relative, t.better = old.better;
          }
        }
      }
      next.metrics = defaults;
      nlohmann::json j = pipeline::ToJson(next);
      j["config"] = std::filesystem::relative(p.scenario->config, baseline.root).string();
      updated.push_back(j);
    }
  }
  WriteFileAtomically(out / "regress.csv", pipeline::ComparisonsToCsv(comparisons));
  const int regressed = static_cast<int>(std::count_if(
      comparisons.begin(), comparisons.end(), [](const pipeline::MetricComparison& c) {
        return c.verdict == pipeline::Verdict::kRegressed ||
               c.verdict == pipeline::Verdict::kMissing;
      }));
  const int improved =
      static_cast<int>(std::count_if(comparisons.begin(), comparisons.end(), [](const auto& c) {
        return c.verdict == pipeline::Verdict::kImproved;
      }));
  nlohmann::json summary = {{"baseline", baseline.file.string()},
                            {"metrics", comparisons.size()},
                            {"regressed", regressed},
                            {"improved", improved},
                            {"scenarios", report}};
  WriteFileAtomically(out / "regress.json", summary.dump(2) + "\n");
  WriteFileAtomically(out / "run.json",
                      Provenance(argv, summary, args.common.threads, {}).dump(2) + "\n");
  if (args.update) {
    // Scenarios not run this time are kept as they were.
    nlohmann::json scenarios = nlohmann::json::array();
    for (const pipeline::Scenario& s : baseline.scenarios) {
      bool replaced = false;
      for (const nlohmann::json& u : updated) {
        if (u["name"] == s.name) scenarios.push_back(u), replaced = true;
      }
      if (!replaced) {
        nlohmann::json j = pipeline::ToJson(s);
        j["config"] = std::filesystem::relative(s.config, baseline.root).string();
        scenarios.push_back(j);
      }
    }
    std::ifstream in(baseline.file);
    nlohmann::json file = nlohmann::json::parse(in);
    file["scenarios"] = scenarios;
    WriteFileAtomically(baseline.file, file.dump(2) + "\n");
    if (!args.common.quiet)
      std::cout << "regress: baseline updated: " << baseline.file.string() << "\n";
    return;
  }
  if (!args.common.quiet) {
    std::cout << pipeline::FormatComparisons(comparisons);
    std::cout << "regress: " << comparisons.size() << " metrics, " << regressed
              << " regressed or missing, " << improved << " improved; written: " << out.string()
              << "/{regress.csv, regress.json, <scenario>/}\n";
  }
  if (regressed > 0) {
    throw std::runtime_error(std::to_string(regressed) +
                             " metrics regressed (see regress.csv; the table above)");
  }
}

}  // namespace

void AddRegressCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<RegressArgs>();
  CLI::App* cmd = app.add_subcommand(
      "regress", "Run a baseline's scenarios and compare every metric with its tolerance");
  cmd->add_option("--baseline", args->baseline, "Baseline folder (with baseline.json)")->required();
  cmd->add_option("--scenario", args->scenarios, "Run only these scenarios (repeatable)");
  cmd->add_flag("--update", args->update,
                "Write the runs' metrics into the baseline (keeping its tolerances)");
  AddCommonFlags(cmd, &args->common, {.config_help = "", .set = false});
  cmd->callback([args, argv] { RunRegress(*args, argv); });
}

MMH_REGISTER_COMMAND(47, AddRegressCommand);

}  // namespace mmh::cli
