// The mmh executables: one subcommand per user task, thin over the modules (DESIGN.md). This file
// is the main() of both `mmh` (the commands that load no heavy library; compiled with
// MMH_LIGHT_EXECUTABLE) and `mmh-full` (every command): cli/full_executable.h.
// Exit codes: 0 ok, 1 failure of the work, 2 bad input or usage.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/command_registry.h"
#include "cli/full_executable.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  CLI::App app{"mmh: the MotionMontage research harness"};
  app.require_subcommand(1);
  app.set_version_flag("--version", MMH_VERSION);
  for (const mmh::cli::RegisteredCommand& command : mmh::cli::RegisteredCommands()) {
    command.add(app, args);
  }
#ifdef MMH_LIGHT_EXECUTABLE
  if (mmh::cli::NeedsFullExecutable(app, args)) mmh::cli::ExecFullExecutable(args);
#endif
  return mmh::cli::ParseAndRun(app, argc, argv);
}
