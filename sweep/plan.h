// A sweep's plan: every cell (one parameter setting and replicate) with its input config, its
// resolved config and its identity, the hash of that resolved config with the command, its inputs
// and the mmh version (never a running number, so that a cell keeps its folder whatever else the
// sweep holds). Written to DIR/plan.json and DIR/configs/<cell>.json before anything runs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sweep/spec.h"

namespace mmh::sweep {

struct Cell {
  std::string id;  // 16 hex digits
  int point = 0;   // parameter setting (grid x samples), in plan order
  int replicate = 0;
  std::optional<std::uint64_t> seed;                        // the derived seed, if replicated
  std::vector<std::pair<std::string, nlohmann::json>> params;  // axis key -> value, axis order
  nlohmann::json config;                                    // input config (base + sets + axes)
};

// An axis as the aggregation sees it.
struct AxisInfo {
  std::string key;
  bool numeric = true;  // every value a number
  AxisScale scale = AxisScale::kLinear;
  bool sampled = false;  // continuous (samples), not a grid of values
};

struct Plan {
  SweepSpec spec;
  std::string mmh_version;
  std::filesystem::path workdir;  // every cell runs here (the spec's relative paths)
  std::vector<std::string> inputs;  // the command's inputs as command-line arguments
  std::vector<AxisInfo> axes;
  std::vector<Cell> cells;  // points in order, replicates within a point
  int cells_per_worker = 1;
  int points = 0;
};

// Expands the spec into cells and checks every axis key and value, and every cell's config,
// against the command's own options before anything runs: an InputError names the spec file, the
// axis and the value, with the command's "did you mean".
Plan BuildPlan(const SweepSpec& spec, const std::string& mmh_version,
               const std::filesystem::path& workdir);

// The spec as the plan keeps it (the base config inline), for comparing with an earlier sweep.
nlohmann::json NormalizedSpec(const SweepSpec& spec);

// The value at a dotted key path ("montage.labelling.mu", "takes.0.frames": numbers index
// arrays), or nullptr.
const nlohmann::json* FindKey(const nlohmann::json& root, const std::string& key);

// FNV-1a 64 of `text` as 16 hex digits.
std::string HashHex(const std::string& text);

// The derived seed of a cell (sweep/spec.h SeedScheme): its first seed key's.
std::uint64_t DeriveSeed(const Replicates& replicates, const std::string& point_key, int replicate);

// The seed of the cell's seed key number `key_index` (Replicates::seed_keys) from its derived
// seed: the seed itself for the first key, another SplitMix64 draw for each further one (31 bits).
std::uint64_t ReplicateKeySeed(std::uint64_t seed, std::size_t key_index);

// The sample points of a sample set: count rows of axes.size() values in [from, to].
std::vector<std::vector<double>> SamplePoints(const SampleSet& samples);

nlohmann::json PlanToJson(const Plan& plan);
Plan PlanFromJson(const nlohmann::json& json, const std::filesystem::path& file);

// DIR/plan.json, DIR/configs/<cell>.json. Refuses a DIR that holds another spec's sweep (naming
// the keys that differ) or files that are not a sweep's.
void WritePlan(const std::filesystem::path& dir, const Plan& plan);
Plan ReadPlan(const std::filesystem::path& dir);
std::filesystem::path CellConfigPath(const std::filesystem::path& dir, const Cell& cell);

}  // namespace mmh::sweep
