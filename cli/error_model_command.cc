// `mmh error-model`: the fast mode's error model (pipeline/error_model.h) fitted from a per-frame
// table of tracked takes (pipeline/tracking_frames.h; a full-fidelity study's tracking_errors.csv),
// so that a change to the estimator is refitted without running the study again.
#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "pipeline/error_model.h"
#include "pipeline/tracking_frames.h"

namespace mmh::cli {
namespace {

struct ErrorModelArgs {
  CommonFlags common;
  std::string frames;
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunErrorModel(const ErrorModelArgs& args, const std::vector<std::string>& argv) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = LoadConfig(args.common);
  config.RequireOnlySections({"error_model"});
  // The prior: where the table has no data (a view condition never seen) and the lying tilt.
  const auto prior = config.Get<pipeline::ErrorModelOptions>("error_model");
  prior.Validate("error_model");
  const auto limit = LimitThreads(args.common.threads);
  StartGitCommitLookup();

  // Everything is read and fitted before anything is written: bad input leaves no output.
  const std::vector<pipeline::TakeFrames> takes = pipeline::ReadTakeFramesCsv(args.frames);
  if (takes.empty()) {
    throw InputError(args.frames + ": no frames after the header, expected the tracked frames of "
                     "at least one take (nothing to fit)");
  }
  const double read_seconds = SecondsSince(start);
  const auto fit_start = std::chrono::steady_clock::now();
  const pipeline::ErrorModelEstimate estimate = pipeline::EstimateErrorModel(takes, prior);
  const double fit_seconds = SecondsSince(fit_start);

  nlohmann::json resolved;
  resolved["error_model"] = ToJson(prior);
  const std::string origin = "the per-frame table " + args.frames + " (" +
                             std::to_string(takes.size()) + " takes), refitted by mmh error-model.";
  const std::filesystem::path out = args.common.out_dir;
  EnsureDirectory(out);
  WriteFileAtomically(out / "error_model.json", estimate.ToJson().dump(2) + "\n");
  WriteFileAtomically(out / "error_model.inc", estimate.DefaultsSource(origin));
  WriteFileAtomically(out / "config.resolved.json", resolved.dump(2) + "\n");
  const nlohmann::json timings = {
      {"read", read_seconds}, {"fit", fit_seconds}, {"total", SecondsSince(start)}};
  WriteFileAtomically(out / "run.json",
                      Provenance(argv, resolved, args.common.threads, timings).dump(2) + "\n");
  if (!args.common.quiet) {
    const pipeline::ErrorModelOptions& o = estimate.options;
    std::cout << takes.size() << " takes, " << estimate.frames << " frames: "
              << estimate.spike_episodes << " spikes, " << estimate.flip_episodes << " flips, "
              << estimate.loss_episodes << " losses; core sd " << o.rotation_sd << " rad, "
              << o.translation_sd * 1000 << " mm, correlation " << o.correlation
              << (estimate.corrected ? " (corrected by simulation)" : " (moments)") << "\n"
              << "written: " << out.string()
              << "/{error_model.json, error_model.inc, config.resolved.json, run.json}\n";
  }
}

}  // namespace

void AddErrorModelCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<ErrorModelArgs>();
  CLI::App* cmd = app.add_subcommand(
      "error-model",
      "Fit the fast mode's error model from a per-frame table of tracked takes (a full-fidelity "
      "study's tracking_errors.csv)");
  cmd->add_option("--frames", args->frames,
                  "Per-frame table: tracking_errors.csv of `mmh study` at full fidelity")
      ->required();
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config with an 'error_model' section (the prior)"});
  cmd->callback([args, argv] { RunErrorModel(*args, argv); });
}

MMH_REGISTER_COMMAND(57, AddErrorModelCommand);

}  // namespace mmh::cli
