// The mmh executable: one subcommand per user task, thin over the modules (DESIGN.md).
// Exit codes: 0 ok, 1 failure of the work, 2 bad input or usage.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli/argument_checks.h"
#include "cli/command_registry.h"
#include "core/error.h"
#include "core/error_text.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  CLI::App app{"mmh: the MotionMontage research harness"};
  app.require_subcommand(1);
  app.set_version_flag("--version", MMH_VERSION);
  for (const mmh::cli::RegisteredCommand& command : mmh::cli::RegisteredCommands()) {
    command.add(app, args);
  }
  try {
    std::vector<std::string> subcommands;
    const CLI::App& const_app = app;
    for (const CLI::App* sub : const_app.get_subcommands([](const CLI::App*) { return true; })) {
      subcommands.push_back(sub->get_name());
    }
    mmh::cli::CheckArguments(args, subcommands);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 echoes the offending value whole (a 2 MB argument, control characters): shortened.
    std::cerr << "mmh: error: " << mmh::EscapeForMessage(e.what(), 300) << '\n'
              << "Run with --help for more information.\n";
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
