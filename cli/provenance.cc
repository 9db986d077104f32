#include "cli/provenance.h"

#include <tbb/version.h>
#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <future>
#include <memory>

#include "core/config_hash.h"
#include "core/library_versions.h"
#include "sim/library_versions.h"
#include "track/library_versions.h"

#ifndef MMH_SOURCE_DIR
#define MMH_SOURCE_DIR "."
#endif

namespace mmh::cli {
namespace {

std::string Run(const std::string& command) {
  std::array<char, 256> buffer{};
  std::string output;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return "";
  while (fgets(buffer.data(), buffer.size(), pipe.get())) output += buffer.data();
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
  return output;
}

// The answer, asked once per process (a sweep worker runs many cells).
std::shared_future<std::string>& GitCommitLookup() {
  static std::shared_future<std::string> commit = std::async(std::launch::async, [] {
    const std::string dir = MMH_SOURCE_DIR;
    const std::string head = Run("git -C '" + dir + "' rev-parse HEAD 2>/dev/null");
    if (head.empty()) return std::string("unknown");
    const std::string dirty =
        Run("git -C '" + dir + "' status --porcelain --untracked-files=no 2>/dev/null");
    return dirty.empty() ? head : head + "-dirty";
  }).share();
  return commit;
}

}  // namespace

std::string GitCommit() { return GitCommitLookup().get(); }

void StartGitCommitLookup() { GitCommitLookup(); }

nlohmann::json Provenance(const std::vector<std::string>& argv,
                          const nlohmann::json& resolved_config, int threads,
                          const nlohmann::json& timings) {
  nlohmann::json run;
  // The marker by which a later run recognises the folder as mmh's (kMmhMarkerFiles).
  run["writer"] = "mmh";
  run["command"] = argv;
  // Relative paths in the command and the results are relative to it (mmh report reads the takes).
  run["working_directory"] = std::filesystem::current_path().string();
  run["mmh_version"] = MMH_VERSION;
  run["git_commit"] = GitCommit();
  run["config_hash"] = ConfigHash(resolved_config);
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  run["host"] = host;
  run["threads"] = threads;
  run["hardware_threads"] = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  run["libraries"] = {
      {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
                    "." + std::to_string(EIGEN_MINOR_VERSION)},
      {"tbb", TBB_VERSION_STRING},
      {"nlohmann_json", std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." +
                            std::to_string(NLOHMANN_JSON_VERSION_MINOR) + "." +
                            std::to_string(NLOHMANN_JSON_VERSION_PATCH)},
      {"compiler", __VERSION__},
  };
  for (const nlohmann::json& more :
       {mmh::LibraryVersions(), mmh::sim::LibraryVersions(), mmh::track::LibraryVersions()}) {
    run["libraries"].update(more);
  }
  // Every seed of the resolved config, by key path (the run is a function of config and seeds).
  nlohmann::json seeds = nlohmann::json::object();
  std::function<void(const nlohmann::json&, const std::string&)> find_seeds =
      [&](const nlohmann::json& j, const std::string& path) {
        if (!j.is_object()) return;
        for (const auto& [key, value] : j.items()) {
          const std::string p = path.empty() ? key : path + "." + key;
          if (key == "seed" && value.is_number()) seeds[p] = value;
          find_seeds(value, p);
        }
      };
  find_seeds(resolved_config, "");
  run["seeds"] = seeds;
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  run["finished_utc"] = stamp;
  run["seconds"] = timings;
  return run;
}

}  // namespace mmh::cli
