// The identity of a resolved config: run.json's "config_hash" and a baseline scenario's, which
// `mmh regress` compares to tell a changed default from a changed result.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace mmh {

// FNV-1a 64-bit hash of the config's canonical dump (keys sorted, no spaces), as 16 hex digits.
std::string ConfigHash(const nlohmann::json& resolved_config);

}  // namespace mmh
