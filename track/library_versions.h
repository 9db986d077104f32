// Versions of the third-party libraries track/ uses inside its .cc files, for run.json (the CLI
// never includes their headers).
#pragma once

#include <nlohmann/json.hpp>

namespace mmh::track {

// {"name": "version", ...}
nlohmann::json LibraryVersions();

}  // namespace mmh::track
