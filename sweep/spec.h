// A sweep spec (configs/sweeps/*.json, docs/sweeps.md): the command every cell runs, its base
// config and inputs, the axes (value lists, linear/log ranges, random or Latin-hypercube samples),
// replicates with derived seeds, and the metrics to gather. Only the spec's own structure is
// checked here; the axes are checked against the command's options by BuildPlan (sweep/plan.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace mmh::sweep {

// The subcommands a sweep can run.
enum class SweepCommand { kRun, kStudy, kCompose, kTrack };
const char* CommandName(SweepCommand command);

enum class AxisScale { kLinear, kLog };

// One grid axis: its values in order (a list, or a linear/log range expanded by LoadSpec).
struct GridAxis {
  std::string key;                    // config key path, e.g. "montage.labelling.mu"
  std::vector<nlohmann::json> values;  // at least one
  AxisScale scale = AxisScale::kLinear;  // how plots space it (log ranges: log)
};

// One sampled axis: a continuous interval sampled `SampleSet::count` times.
struct SampledAxis {
  std::string key;
  double from = 0.0;
  double to = 1.0;
  AxisScale scale = AxisScale::kLinear;
  bool integer = false;  // round each sample to the nearest integer
};

enum class SampleMethod { kRandom, kLatinHypercube };

// Random or Latin-hypercube samples of several axes jointly (McKay, Beckman, Conover 1979: each
// axis's interval cut into `count` equal strata, one sample per stratum, strata paired by
// independent random permutations). Crossed with the grid.
struct SampleSet {
  SampleMethod method = SampleMethod::kLatinHypercube;
  int count = 0;
  std::uint64_t seed = 1;
  std::vector<SampledAxis> axes;
};

enum class SeedScheme {
  kPerCell,  // each cell and replicate its own seed (hash of the parameters and replicate)
  kCommon,   // replicate r has the same seed at every parameter setting (common random numbers)
};

struct Replicates {
  int count = 1;
  // Config keys each replicate's seeds go to (empty when count is 1 and the command has none):
  // the first gets the derived seed, each further key a seed derived from it
  // (ReplicateKeySeed). By default run seeds population.seed, and study population.seed and
  // study.seed (new people and new scorers, as StudyConfig::ForReplicate does): a study replicate
  // that kept study.seed would share its scorers' design, tastes and judgement noise with every
  // other cell.
  std::vector<std::string> seed_keys;
  SeedScheme scheme = SeedScheme::kPerCell;
  std::uint64_t seed = 1;  // mixed into every derived seed
};

// Whether the cells set seed_keys: with several replicates, or one per cell under kPerCell.
inline bool Seeded(const Replicates& replicates) {
  return !replicates.seed_keys.empty() &&
         (replicates.count > 1 || replicates.scheme == SeedScheme::kPerCell);
}

enum class Statistic { kMean, kSd, kCi95, kMin, kMax, kMedian };
const char* StatisticName(Statistic statistic);

// A metric: one number per cell, read from a JSON file of the command's output.
struct Metric {
  std::string name;                  // column name in results.csv
  std::string file;                  // relative to the command's output folder
  std::string key;                   // dotted path, array indices as numbers: "takes.0.frames"
  std::vector<Statistic> statistics;  // columns in summary.csv
};

struct SlurmOptions {
  std::string partition;           // "" = the cluster's default
  std::string time_limit;          // sbatch --time ("" = the partition's default)
  int throttle = 0;                // --array=...%K (0 = no throttle)
  int max_array_size = 0;          // 0 = ask `scontrol show config` (MaxArraySize)
  int cells_per_task = 0;          // 0 = as cells_per_worker
  std::vector<std::string> sbatch_args;  // more sbatch options, as given
};

struct SweepSpec {
  std::filesystem::path file;  // where it was read from (for messages)
  SweepCommand command = SweepCommand::kRun;
  std::string description;
  nlohmann::json base_config = nlohmann::json::object();  // the file's or inline config
  std::string base_config_file;                           // "" when inline
  std::vector<std::string> sets;                          // applied after the base config
  nlohmann::json inputs = nlohmann::json::object();       // command inputs (takes, ...)
  std::vector<GridAxis> grid;
  SampleSet samples;  // count 0: none
  Replicates replicates;
  std::vector<Metric> metrics;
  int cells_per_worker = 0;  // 0: automatic (packs short commands)
  SlurmOptions slurm;
  nlohmann::json json;  // the spec as read, with the CLI's --set applied (kept in the plan)
};

// Reads and checks a spec: unknown keys (with "did you mean"), wrong types, empty axes, a sample
// count of 0 or ranges that cannot be expanded are InputErrors naming the file, the axis and the
// value. `sets` are "key.path=value" overrides of the spec itself (e.g. "replicates.count=5").
SweepSpec LoadSpec(const std::filesystem::path& file, const std::vector<std::string>& sets = {});

// The same from JSON already in memory (`file` only names it in messages).
SweepSpec ParseSpec(const nlohmann::json& json, const std::filesystem::path& file);

// Expands a range: `count` values from `from` to `to` inclusive, evenly spaced (linear) or evenly
// spaced in log (both ends > 0). Integer ranges are rounded and deduplicated.
std::vector<double> ExpandRange(double from, double to, int count, AxisScale scale);

}  // namespace mmh::sweep
