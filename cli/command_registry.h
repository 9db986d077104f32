// Subcommands register themselves here, so that a new one is a new .cc file in cli/ and nothing
// else: in that file,
//
//   MMH_REGISTER_COMMAND(40, AddTrackCommand);
//
// where AddTrackCommand(CLI::App&, const std::vector<std::string>& argv) adds the subcommand
// (argv is kept for run.json). `order` sorts the subcommands in `mmh --help`.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

using AddCommandFunction = void (*)(CLI::App& app, const std::vector<std::string>& argv);

struct RegisteredCommand {
  int order = 0;
  AddCommandFunction add = nullptr;
};

// Every registered command, sorted by order (ties by registration, which is unspecified).
std::vector<RegisteredCommand> RegisteredCommands();

// Parses the command line into `app` and runs the chosen subcommand; returns the exit code (0 ok,
// 1 failure of the work, 2 bad input or usage) after printing any error to stderr. main() and the
// sweep worker (which runs cells in-process) share it.
int ParseAndRun(CLI::App& app, int argc, char** argv);

// Called by MMH_REGISTER_COMMAND during static initialisation.
bool RegisterCommand(int order, AddCommandFunction add);

}  // namespace mmh::cli

#define MMH_REGISTER_COMMAND_CONCAT_(a, b) a##b
#define MMH_REGISTER_COMMAND_NAME_(line) MMH_REGISTER_COMMAND_CONCAT_(mmh_registered_command_, line)
#define MMH_REGISTER_COMMAND(order, function)                               \
  [[maybe_unused]] static const bool MMH_REGISTER_COMMAND_NAME_(__LINE__) = \
      ::mmh::cli::RegisterCommand(order, function)
