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
nlohmann::json ResolveCommandConfig(SweepCommand command, const Config& config);

// The command-line inputs of every cell from the spec's "inputs" (e.g. compose: takes,
// annotations), checked: unknown inputs, missing required ones and missing files are InputErrors
// naming the spec file and the input.
std::vector<std::string> CommandInputs(const SweepSpec& spec);

// Whether a cell of `command` is short enough that several share one worker process by default.
bool PacksByDefault(SweepCommand command);

}  // namespace mmh::sweep
