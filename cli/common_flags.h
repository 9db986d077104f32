// The flags every subcommand shares (DESIGN.md, "Command line"): --config, --set, --out,
// --threads, --quiet, registered in one place with one meaning, and what every command does with
// them: load the config with the overrides, limit the worker threads, show progress on a terminal.
#pragma once

#include <chrono>
#include <cstdint>
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

// Which of the common flags a subcommand has, and the words of its help that differ.
struct CommonFlagsSpec {
  std::string config_help = "JSON config";  // empty: no --config
  bool config_required = false;
  bool set = true;                         // --set key.path=value, repeatable
  std::string set_help = "Override: key.path=value (JSON value), repeatable";
  std::string out_help = "Output folder";  // empty: no --out
  bool out_required = true;
  bool threads = true;
  std::string threads_help = "Worker threads, 1 to 1024 (default: all cores)";
  bool quiet = true;
};

// Adds the flags `spec` asks for to `command`, storing into `flags` (which must outlive parsing).
void AddCommonFlags(CLI::App* command, CommonFlags* flags, const CommonFlagsSpec& spec = {});

// The config file (if any) with the --set overrides applied.
Config LoadConfig(const CommonFlags& common);

// Limits oneTBB to `threads` worker threads while the returned handle lives (0: no limit).
std::shared_ptr<void> LimitThreads(int threads);

// Whether progress should be drawn: stderr is a terminal and --quiet is not given.
bool ShowProgress(const CommonFlags& common);

// The one progress display of the commands: a bar on stderr (done / total, rate, time left), or
// a count and rate when the total is not known (total <= 0: a live sensor), or nothing when
// disabled. The line ends when done reaches total, or with Finish().
class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string label, std::string unit = "frames");
  void Update(std::int64_t done, std::int64_t total);
  // Ends the line (when something was drawn and the total was not reached).
  void Finish();
  ~ProgressBar() { Finish(); }

 private:
  bool enabled_;
  std::string label_;
  std::string unit_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  bool open_line_ = false;  // something drawn since the last newline
};

}  // namespace mmh::cli
