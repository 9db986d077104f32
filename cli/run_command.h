// `mmh run` (one animator end to end) and the scenario runner `mmh regress` shares with it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pipeline/animator_run.h"

namespace CLI {
class App;
}

namespace mmh::cli {

// Runs one animator and writes everything into `out` (pipeline/run_output.h, config.resolved.json
// and run.json). The takes that finished are written even when a later stage fails. `resume`
// reuses the takes an earlier run in `out` finished (InputError when its config differs in more
// than the montage and metrics sections, or its files do not belong to this run).
pipeline::AnimatorRun RunScenario(const pipeline::RunConfig& config,
                                  const std::filesystem::path& out, bool progress_bar,
                                  const std::vector<std::string>& argv, int threads,
                                  bool resume = false);

void AddRunCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
