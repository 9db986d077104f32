// `mmh compose`: a montage from take trajectories (TUM) and annotations (CSV).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh {
class Config;
}

namespace mmh::cli {

struct CommonFlags {
  std::string config_file;
  std::vector<std::string> sets;
  std::string out_dir;
  int threads = 0;
  bool quiet = false;
};

// The config file (if any) with the --set overrides applied.
Config LoadConfig(const CommonFlags& common);

// Limits oneTBB to `threads` worker threads while the returned handle lives (0: no limit).
std::shared_ptr<void> LimitThreads(int threads);

// Registers the subcommand; `argv` is kept for run.json.
void AddComposeCommand(CLI::App& app, const std::vector<std::string>& argv);

}  // namespace mmh::cli
