// `mmh calibrate`: the simulated people calibrated to the paper's numbers from a finished
// calibration sweep (calibrate/calibration.h, docs/calibration.md).
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

// Registers the subcommand; `argv` is kept for run.json.
void AddCalibrateCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
