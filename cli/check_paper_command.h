// `mmh check-paper`: consistency audit of the paper's reported statistics
// (study/paper_audit.h; the reported numbers in configs/paper_reported.json).
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

// Registers the subcommand; `argv` is kept for run.json.
void AddCheckPaperCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
