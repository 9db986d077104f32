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
// Compose is built in; run, study and track need a registered ConfigResolver (a std::logic_error
// without one).
nlohmann::json ResolveCommandConfig(SweepCommand command, const Config& config);

// How the configs of run, study and track are resolved. The code that reads them links the
// renderer and the tracker (Embree, PCL, OpenCV, OpenImageIO), so it is not part of mmh::sweep:
// sweep/command_resolvers.cc registers it at start-up, in the programs that link the object
// library mmh::sweep_resolvers (mmh-full, the tests), and the light mmh, which runs compose
// sweeps only, links none of it (docs/architecture.md, "Start-up").
using ConfigResolver = nlohmann::json (*)(const Config& config);
bool RegisterConfigResolver(SweepCommand command, ConfigResolver resolver);

// The command-line inputs of every cell from the spec's "inputs" (e.g. compose: takes,
// annotations), checked: unknown inputs, missing required ones and missing files are InputErrors
// naming the spec file and the input.
std::vector<std::string> CommandInputs(const SweepSpec& spec);

// Whether a cell of `command` is short enough that several share one worker process by default.
bool PacksByDefault(SweepCommand command);

}  // namespace mmh::sweep
