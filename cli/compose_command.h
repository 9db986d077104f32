// `mmh compose`: a montage from take trajectories (TUM) and annotations (CSV).
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

// Registers the subcommand; `argv` is kept for run.json.
void AddComposeCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
