// The command line is two executables with one command registry (docs/architecture.md,
// "Start-up"). `mmh` links only the commands that load no heavy library at start (compose,
// stats, sweep, check-paper, eval, export, report) and starts in milliseconds; `mmh-full`, built
// beside it, links every command. `mmh` hands everything else (the other commands, --help, usage
// errors) to `mmh-full` by exec, with the same arguments, so both print the same help, errors and
// exit codes.
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace mmh::cli {

// Whether `app` has the subcommand `name`.
bool HasCommand(const CLI::App& app, const std::string& name);

// Whether this executable has the subcommand `name` (its own registry of commands).
bool HasCommand(const std::string& name);

// Whether `mmh ARGS...` must run in mmh-full: the first argument is neither a command of `app`
// (this executable's commands) nor --version.
bool NeedsFullExecutable(const CLI::App& app, const std::vector<std::string>& args);

// The name of the executable with every command, in the folder of `mmh`.
inline constexpr const char* kFullExecutableName = "mmh-full";

// Replaces this process with mmh-full (kFullExecutableName in this executable's folder), with the
// same arguments (argv[0] included). If that fails: prints why and exits with 1.
[[noreturn]] void ExecFullExecutable(const std::vector<std::string>& args);

// Hands the command to mmh-full (ExecFullExecutable(args)) when it runs in full fidelity and this
// program does not link the recorded sessions (pipeline::FullFidelityLinked): the light `mmh`
// runs `run` and `study` in fast fidelity itself. Called once the config is read and checked, so
// both programs report bad configs alike.
void RequireFidelityHere(bool full_fidelity, const std::vector<std::string>& args);

}  // namespace mmh::cli
