#include "cli/calibrate_command.h"

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>
#include <memory>

#include "calibrate/calibration.h"
#include "calibrate/targets.h"
#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "core/error.h"

namespace mmh::cli {
namespace {

struct CalibrateArgs {
  CommonFlags common;
  std::string sweep;
  std::string targets = "configs/calibration/paper_targets.json";
};

void RunCalibrate(const CalibrateArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  Config config = LoadConfig(args.common);
  config.RequireOnlySections({"calibration"});
  const auto options = config.Get<calibrate::CalibrationOptions>("calibration");
  const calibrate::Targets targets = calibrate::LoadTargets(args.targets);
  const auto threads = LimitThreads(args.common.threads);
  ProgressBar bar(ShowProgress(args.common), "calibrate: predictive check", "studies");
  const calibrate::CalibrationResult result =
      calibrate::Calibrate(args.sweep, targets, options, [&](int done, int total) {
        bar.Update(done, total);
      });
  nlohmann::json resolved;
  resolved["calibration"] = ToJson(options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  calibrate::WriteCalibration(args.common.out_dir, result, targets,
                              Provenance(argv, resolved, args.common.threads, {{"total", seconds}}));
  if (!args.common.quiet) {
    std::cout << "calibrated " << result.parameters.size() << " parameters on "
              << result.simulations.size() << " simulated studies (" << result.cells
              << " cells); predictive check over " << result.ppc_values.size() << " studies\n";
    for (std::size_t j = 0; j < result.parameters.size(); ++j) {
      const auto& p = result.abc.posterior[j];
      std::cout << "  " << result.parameters[j].key << " = " << FormatNumber(p.median) << "  [90 %: "
                << FormatNumber(p.q05) << ", " << FormatNumber(p.q95) << "]\n";
    }
    std::cout << "written: " << args.common.out_dir
              << "/{report.md, calibration.json, calibrated.json, parameters.csv, posterior.csv, "
                 "identification.csv, targets.csv, conclusions.csv, ppc_replicates.csv, "
                 "config.resolved.json, next_round.json, run.json}\n";
  }
}

}  // namespace

void AddCalibrateCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Calibrates the simulated people to the paper's numbers from a finished calibration sweep "
      "(ABC, identification, posterior predictive check)");
  cmd->add_option("--sweep", args->sweep,
                  "Finished sweep of fast studies over the parameters "
                  "(mmh sweep --spec configs/sweeps/calibrate_people.json)")
      ->required();
  cmd->add_option("--targets", args->targets,
                  "The reported numbers, fit or held out (default: "
                  "configs/calibration/paper_targets.json)");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config with a 'calibration' section (calibration.abc."
                                 "accept_fraction, ppc_replicates, ppc_seed, ppc_draws, "
                                 "next_round.margin/points/replicates, digits)"});
  cmd->callback([args, argv] { RunCalibrate(*args, argv); });
}

MMH_REGISTER_COMMAND(77, AddCalibrateCommand);

}  // namespace mmh::cli
