#include "cli/command_registry.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli/argument_checks.h"
#include "core/error.h"
#include "core/error_text.h"

namespace mmh::cli {
namespace {

// A function-local static, so that registration from other translation units' static
// initialisers never sees an unconstructed vector.
std::vector<RegisteredCommand>& Registry() {
  static std::vector<RegisteredCommand> registry;
  return registry;
}

}  // namespace

std::vector<RegisteredCommand> RegisteredCommands() {
  std::vector<RegisteredCommand> commands = Registry();
  std::stable_sort(
      commands.begin(), commands.end(),
      [](const RegisteredCommand& a, const RegisteredCommand& b) { return a.order < b.order; });
  return commands;
}

int ParseAndRun(CLI::App& app, int argc, char** argv) {
  try {
    std::vector<std::string> subcommands;
    const CLI::App& const_app = app;
    for (const CLI::App* sub : const_app.get_subcommands([](const CLI::App*) { return true; })) {
      subcommands.push_back(sub->get_name());
    }
    CheckArguments(std::vector<std::string>(argv, argv + argc), subcommands);
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

bool RegisterCommand(int order, AddCommandFunction add) {
  Registry().push_back({order, add});
  return true;
}

}  // namespace mmh::cli
