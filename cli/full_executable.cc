#include "cli/full_executable.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <utility>

#include "cli/command_registry.h"
#include "pipeline/animator_run.h"

namespace mmh::cli {

bool HasCommand(const CLI::App& app, const std::string& name) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->get_name() == name) return true;
  }
  return false;
}

bool HasCommand(const std::string& name) {
  // Each command's Add function names it: added to a scratch app to learn the names.
  CLI::App app;
  for (const RegisteredCommand& command : RegisteredCommands()) command.add(app, {});
  return HasCommand(std::as_const(app), name);
}

bool NeedsFullExecutable(const CLI::App& app, const std::vector<std::string>& args) {
  if (args.size() < 2) return true;
  if (args[1] == "--version") return false;
  return !HasCommand(app, args[1]);
}

void ExecFullExecutable(const std::vector<std::string>& args) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path full = self.parent_path() / kFullExecutableName;
  std::vector<std::string> copy = args;
  std::vector<char*> argv;
  for (std::string& arg : copy) argv.push_back(arg.data());
  argv.push_back(nullptr);
  execv(full.c_str(), argv.data());
  std::cerr << "mmh: failed: cannot start " << full.string() << " (" << std::strerror(errno)
            << "), which runs the commands " << self.filename().string()
            << " does not have; it is built beside "
            << self.filename().string() << " (./mmh build)\n";
  std::exit(1);
}

void RequireFidelityHere(bool full_fidelity, const std::vector<std::string>& args) {
  if (full_fidelity && !pipeline::FullFidelityLinked()) {
    ExecFullExecutable(args);
  }
}

}  // namespace mmh::cli
