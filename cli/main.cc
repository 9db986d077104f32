// The mmh executable: one subcommand per user task, thin over the modules (DESIGN.md).
// Exit codes: 0 ok, 1 failure of the work, 2 bad input or usage.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/command_registry.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  CLI::App app{"mmh: the MotionMontage research harness"};
  app.require_subcommand(1);
  app.set_version_flag("--version", MMH_VERSION);
  for (const mmh::cli::RegisteredCommand& command : mmh::cli::RegisteredCommands()) {
    command.add(app, args);
  }
  return mmh::cli::ParseAndRun(app, argc, argv);
}
