// Provenance of a run (run.json): what produced the results beside it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mmh::cli {

// Git commit of the source tree (with "-dirty" when it has changes), or "unknown".
std::string GitCommit();

// FNV-1a 64-bit hash of the resolved config's canonical dump, as 16 hex digits.
std::string ConfigHash(const nlohmann::json& resolved_config);

// run.json: command line, commit, config hash, library versions, host, threads, timings.
nlohmann::json Provenance(const std::vector<std::string>& argv,
                          const nlohmann::json& resolved_config, int threads,
                          const nlohmann::json& timings);

}  // namespace mmh::cli
