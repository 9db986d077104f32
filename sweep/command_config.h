// What a sweep needs to know of each command it can run: its resolved config (every default
// filled in, every key and value checked by the command's own Options structs, exactly as the
// command itself reads it) and its command-line inputs.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sweep/spec.h"

namespace mmh {
class Config;
}

namespace mmh::sweep {

// The config `mmh <command>` would resolve from `config`; InputError as the command would throw.
// Compose, run and study are built in; track needs a registered ConfigResolver (a
// std::logic_error without one).
nlohmann::json ResolveCommandConfig(SweepCommand command, const Config& config);

// How the config of track is resolved. The code that reads it links the tracker's frame sources
// (OpenImageIO through its plugin, the readers of recordings), so it is not part of mmh::sweep:
// sweep/command_resolvers.cc registers it at start-up, in the programs that link the object
// library mmh::sweep_resolvers (mmh-full, the tests), and the light mmh, which runs compose,
// run and study sweeps, links none of it (docs/architecture.md, "Start-up").
using ConfigResolver = nlohmann::json (*)(const Config& config);
bool RegisterConfigResolver(SweepCommand command, ConfigResolver resolver);

// Whether a cell of `command` with this resolved config (ResolveCommandConfig) renders and tracks
// frames: run and study in full fidelity (run.fidelity). The light mmh hands such sweeps to
// mmh-full (cli/sweep_command.cc).
bool NeedsFullFidelity(SweepCommand command, const nlohmann::json& resolved);

// The command-line inputs of every cell from the spec's "inputs" (e.g. compose: takes,
// annotations), checked: unknown inputs, missing required ones and missing files are InputErrors
// naming the spec file and the input.
std::vector<std::string> CommandInputs(const SweepSpec& spec);

// Whether a cell of `command` is short enough that several share one worker process by default.
bool PacksByDefault(SweepCommand command);

}  // namespace mmh::sweep
