// `mmh stats`: the user study's statistics (study/study_analysis.h) on study data in CSV files
// (study/study_data.h, docs/statistics.md).
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

// Registers the subcommand; `argv` is kept for run.json.
void AddStatsCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
