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
  std::vector<pipeline::PreparedScenario> runs;
  for (const pipeline::Scenario& scenario : baseline.scenarios) {
    if (args.scenarios.empty() || std::find(args.scenarios.begin(), args.scenarios.end(),
                                            scenario.name) != args.scenarios.end()) {
      runs.push_back(pipeline::PrepareScenario(baseline, scenario));
    }
  }
  const auto threads = LimitThreads(args.common.threads);
  const std::filesystem::path out = args.common.out_dir;
  EnsureDirectory(out);
  const bool bar = ShowProgress(args.common);
  std::vector<pipeline::MetricComparison> comparisons;
  std::vector<pipeline::Scenario> updated;
  nlohmann::json report = nlohmann::json::array();
  // Per scenario: its stages' wall times, for run.json only (regress.json, like every result file,
  // is a function of the baseline and the code).
  nlohmann::json seconds = nlohmann::json::object();
  for (const pipeline::PreparedScenario& p : runs) {
    if (!args.common.quiet && !p.scenario->config_hash.empty() &&
        p.scenario->config_hash != p.config_hash) {
      std::cerr << "regress: " << p.scenario->name << ": the resolved config differs from the "
                << "baseline's (hash " << p.config_hash << ", baseline " << p.scenario->config_hash
                << "): a default changed; differences may come from that\n";
    }
    const pipeline::AnimatorRun run =
        RunScenario(p.config, out / p.scenario->name, bar, argv, args.common.threads);
    const nlohmann::json metrics = pipeline::ToJson(*run.metrics);
    const auto c = pipeline::CompareWithBaseline(*p.scenario, metrics);
    comparisons.insert(comparisons.end(), c.begin(), c.end());
    report.push_back({{"scenario", p.scenario->name}, {"config_hash", p.config_hash}});
    seconds[p.scenario->name] = pipeline::SecondsToJson(run);
    if (args.update) updated.push_back(pipeline::UpdatedScenario(*p.scenario, metrics, p.config_hash));
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
                      Provenance(argv, summary, args.common.threads, seconds).dump(2) + "\n");
  if (args.update) {
    pipeline::WriteBaseline(baseline, updated);
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
