// Provenance of a run (run.json): what produced the results beside it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mmh::cli {

// Git commit of the source tree (with "-dirty" when it has changes), or "unknown". Asked of git
// once per process (two git processes, 30-80 ms on this machine).
std::string GitCommit();

// Starts asking git in the background, so that GitCommit() finds the answer ready: commands call
// it once their input is checked, before their work, which hides git's time behind it.
void StartGitCommitLookup();

// run.json: command line, commit, config hash (core/config_hash.h), library versions, host, threads, timings.
nlohmann::json Provenance(const std::vector<std::string>& argv,
                          const nlohmann::json& resolved_config, int threads,
                          const nlohmann::json& timings);

}  // namespace mmh::cli
