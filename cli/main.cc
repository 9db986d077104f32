// The mmh executable: one subcommand per user task, thin over the modules (DESIGN.md).
// Exit codes: 0 ok, 1 failure of the work, 2 bad input or usage.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli/command_registry.h"
#include "core/error.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  CLI::App app{"mmh: the MotionMontage research harness"};
  app.require_subcommand(1);
  app.set_version_flag("--version", MMH_VERSION);
  for (const mmh::cli::RegisteredCommand& command : mmh::cli::RegisteredCommands()) {
    command.add(app, args);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const mmh::InputError& e) {
    std::cerr << "mmh: error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mmh: failed: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
