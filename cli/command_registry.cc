#include "cli/command_registry.h"

#include <algorithm>

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

bool RegisterCommand(int order, AddCommandFunction add) {
  Registry().push_back({order, add});
  return true;
}

}  // namespace mmh::cli
