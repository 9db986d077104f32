// Versions of the third-party libraries sim/ uses inside its .cc files, for run.json (the CLI
// never includes their headers).
#pragma once

#include <nlohmann/json.hpp>

namespace mmh::sim {

// {"name": "version", ...}
nlohmann::json LibraryVersions();

}  // namespace mmh::sim
