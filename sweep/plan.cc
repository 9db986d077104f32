#include "sweep/plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/options.h"
#include "core/stale_temporaries.h"
#include "core/text_parsing.h"
#include "sweep/command_config.h"

namespace mmh::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// SplitMix64 (Steele, Lea, Flood 2014): a portable generator, so that samples and seeds are the
// same bytes on every platform and standard library (std:: distributions are not).
std::uint64_t SplitMix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double Uniform01(std::uint64_t& state) {
  return static_cast<double>(SplitMix64(state) >> 11) * 0x1.0p-53;
}

std::uint64_t HashValue(const std::string& text) {
  std::uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : text) hash = (hash ^ c) * 1099511628211ull;
  return hash;
}

std::string Assignment(const std::string& key, const json& value) {
  return key + "=" + value.dump();
}

double MapSample(const SampledAxis& axis, double u) {
  double v = axis.scale == AxisScale::kLog
                 ? std::exp(std::log(axis.from) + u * (std::log(axis.to) - std::log(axis.from)))
                 : axis.from + u * (axis.to - axis.from);
  return axis.integer ? std::round(v) : v;
}

std::string DescribeAxis(const SweepSpec& spec, const std::string& key) {
  for (std::size_t i = 0; i < spec.grid.size(); ++i) {
    if (spec.grid[i].key == key) return "axes[" + std::to_string(i) + "] (" + key + ")";
  }
  for (std::size_t i = 0; i < spec.samples.axes.size(); ++i) {
    if (spec.samples.axes[i].key == key) {
      return "samples.axes[" + std::to_string(i) + "] (" + key + ")";
    }
  }
  return "replicates.seed_key (" + key + ")";
}

// The keys (leaves) of a resolved config, for "did you mean".
void Leaves(const json& j, const std::string& prefix, std::vector<std::string>* out) {
  if (!j.is_object()) {
    out->push_back(prefix);
    return;
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    Leaves(it.value(), prefix.empty() ? it.key() : prefix + "." + it.key(), out);
  }
}

}  // namespace

const json* FindKey(const json& root, const std::string& key) {
  const json* node = &root;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = key.find('.', start);
    const std::string name = key.substr(start, dot == std::string::npos ? dot : dot - start);
    if (node->is_object()) {
      const auto it = node->find(name);
      if (it == node->end()) return nullptr;
      node = &*it;
    } else if (node->is_array()) {
      char* end = nullptr;
      const long index = std::strtol(name.c_str(), &end, 10);
      if (name.empty() || *end != '\0' || index < 0 || index >= static_cast<long>(node->size())) {
        return nullptr;
      }
      node = &(*node)[index];
    } else {
      return nullptr;
    }
    if (dot == std::string::npos) return node;
    start = dot + 1;
  }
}

std::string HashHex(const std::string& text) {
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx", static_cast<unsigned long long>(HashValue(text)));
  return hex;
}

std::uint64_t DeriveSeed(const Replicates& replicates, const std::string& point_key,
                         int replicate) {
  std::uint64_t state = replicates.seed * 0x2545f4914f6cdd1dull + static_cast<std::uint64_t>(replicate);
  if (replicates.scheme == SeedScheme::kPerCell) state ^= HashValue(point_key);
  // 31 bits: any integer seed field of any command holds it.
  return SplitMix64(state) & 0x7fffffffull;
}

std::uint64_t ReplicateKeySeed(std::uint64_t seed, std::size_t key_index) {
  if (key_index == 0) return seed;
  std::uint64_t state = seed * 0x9e3779b97f4a7c15ull + key_index;
  return SplitMix64(state) & 0x7fffffffull;
}

std::vector<std::vector<double>> SamplePoints(const SampleSet& samples) {
  const int n = samples.count;
  const std::size_t d = samples.axes.size();
  std::uint64_t state = samples.seed;
  std::vector<std::vector<double>> points(n, std::vector<double>(d));
  for (std::size_t a = 0; a < d; ++a) {
    std::vector<int> strata(n);
    std::iota(strata.begin(), strata.end(), 0);
    if (samples.method == SampleMethod::kLatinHypercube) {
      // Fisher-Yates with the portable generator.
      for (int i = n - 1; i > 0; --i) {
        const int j = static_cast<int>(SplitMix64(state) % static_cast<std::uint64_t>(i + 1));
        std::swap(strata[i], strata[j]);
      }
    }
    for (int i = 0; i < n; ++i) {
      const double u = samples.method == SampleMethod::kLatinHypercube
                           ? (strata[i] + Uniform01(state)) / n
                           : Uniform01(state);
      points[i][a] = MapSample(samples.axes[a], u);
    }
  }
  return points;
}

json NormalizedSpec(const SweepSpec& spec) {
  json j = spec.json;
  j["config"] = spec.base_config;
  if (!spec.base_config_file.empty()) j["config_file"] = spec.base_config_file;
  j["set"] = spec.sets;
  return j;
}

namespace {

using Point = std::vector<std::pair<std::string, json>>;  // axis key -> value, axis order

// The base config and the sets, as the command would read them (a file keeps its name in
// messages).
Config BaseConfig(const SweepSpec& spec) {
  Config base;
  if (!spec.base_config_file.empty()) {
    base = Config::Load(spec.base_config_file);
  } else {
    for (auto it = spec.base_config.begin(); it != spec.base_config.end(); ++it) {
      base.Set(it.key() + "=" + it.value().dump());
    }
  }
  for (const auto& set : spec.sets) base.Set(set);
  return base;
}

// The axes as the aggregation sees them: the grid's, then the samples'.
std::vector<AxisInfo> AxesOf(const SweepSpec& spec) {
  std::vector<AxisInfo> axes;
  for (const auto& axis : spec.grid) {
    AxisInfo info{axis.key, true, axis.scale, false};
    for (const auto& v : axis.values) info.numeric = info.numeric && v.is_number();
    axes.push_back(info);
  }
  for (const auto& axis : spec.samples.axes) axes.push_back({axis.key, true, axis.scale, true});
  return axes;
}

// Checks each axis key and value (and the replicates' seed key) alone on the base config: the
// first error names the spec file, the axis and the value, with the command's "did you mean".
class AxisChecker {
 public:
  AxisChecker(const SweepSpec& spec, const Config& base) : spec_(spec), base_(base) {
    try {
      base_resolved_ = ResolveCommandConfig(spec.command, base);
    } catch (const InputError& e) {
      throw InputError(File() + ": the base config (config and set): " + e.what());
    }
    Leaves(base_resolved_, "", &leaves_);
  }

  void CheckAll() const {
    for (const auto& axis : spec_.grid) {
      CheckKey(axis.key);
      for (const auto& v : axis.values) CheckValue(axis.key, v);
    }
    for (const auto& axis : spec_.samples.axes) {
      CheckKey(axis.key);
      for (double v : {axis.from, axis.to}) {
        CheckValue(axis.key, axis.integer ? json(static_cast<long long>(std::round(v))) : json(v));
      }
    }
    for (const std::string& key : spec_.replicates.seed_keys) CheckKey(key);
  }

 private:
  std::string File() const { return spec_.file.string(); }

  void CheckKey(const std::string& key) const {
    const json* value = FindKey(base_resolved_, key);
    if (value && !value->is_object()) return;
    const std::string suggestion = options_internal::SuggestName(key, leaves_);
    throw InputError(File() + ": " + DescribeAxis(spec_, key) + ": '" + key + "' is " +
                     (value ? "a section, not an option," : "not an option") + " of `mmh " +
                     CommandName(spec_.command) + "`" +
                     (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)"));
  }

  void CheckValue(const std::string& key, const json& value) const {
    Config config = base_;
    config.Set(Assignment(key, value));
    try {
      ResolveCommandConfig(spec_.command, config);
    } catch (const InputError& e) {
      throw InputError(File() + ": " + DescribeAxis(spec_, key) + " value " + value.dump() + ": " +
                       e.what());
    }
  }

  const SweepSpec& spec_;
  const Config& base_;
  json base_resolved_;
  std::vector<std::string> leaves_;
};

// The parameter settings: the grid (first axis slowest) crossed with the samples.
std::vector<Point> ExpandPoints(const SweepSpec& spec) {
  std::vector<Point> points(1);
  for (const auto& axis : spec.grid) {
    std::vector<Point> next;
    for (const auto& p : points) {
      for (const auto& v : axis.values) {
        next.push_back(p);
        next.back().emplace_back(axis.key, v);
      }
    }
    points = std::move(next);
  }
  if (spec.samples.count > 0) {
    const auto samples = SamplePoints(spec.samples);
    std::vector<Point> next;
    for (const auto& p : points) {
      for (const auto& s : samples) {
        next.push_back(p);
        for (std::size_t a = 0; a < s.size(); ++a) {
          const auto& axis = spec.samples.axes[a];
          next.back().emplace_back(axis.key,
                                   axis.integer ? json(static_cast<long long>(s[a])) : json(s[a]));
        }
      }
    }
    points = std::move(next);
  }
  return points;
}

json PointKey(const Point& point) {
  json key = json::array();
  for (const auto& [k, v] : point) key.push_back({k, v});
  return key;
}

// Replicate `r` of the setting `point` (number `p`): its config (base, axis values, derived
// seed), resolved by the command to give its identity.
Cell MakeCell(const Plan& plan, const Config& base, const Point& point, int p, int r,
              bool seeded) {
  const SweepSpec& spec = plan.spec;
  const json point_key = PointKey(point);
  Cell cell;
  cell.point = p;
  cell.replicate = r;
  cell.params = point;
  Config config = base;
  for (const auto& [k, v] : point) config.Set(Assignment(k, v));
  if (seeded) {
    cell.seed = DeriveSeed(spec.replicates, point_key.dump(), r);
    for (std::size_t k = 0; k < spec.replicates.seed_keys.size(); ++k) {
      config.Set(Assignment(spec.replicates.seed_keys[k], ReplicateKeySeed(*cell.seed, k)));
    }
  }
  json resolved;
  try {
    resolved = ResolveCommandConfig(spec.command, config);
  } catch (const InputError& e) {
    throw InputError(spec.file.string() + ": the cell " + point_key.dump() +
                     " (a combination of axis values): " + e.what());
  }
  cell.config = config.root();
  cell.id = HashHex(json{{"command", CommandName(spec.command)},
                         {"inputs", plan.inputs},
                         {"resolved", resolved},
                         {"mmh_version", plan.mmh_version}}
                        .dump());
  return cell;
}

// Every replicate of every setting, refusing two cells with one identity.
void AddCells(const Config& base, const std::vector<Point>& points, Plan* plan) {
  const SweepSpec& spec = plan->spec;
  const bool seeded = Seeded(spec.replicates);
  std::map<std::string, std::size_t> ids;
  for (std::size_t p = 0; p < points.size(); ++p) {
    for (int r = 0; r < spec.replicates.count; ++r) {
      Cell cell = MakeCell(*plan, base, points[p], static_cast<int>(p), r, seeded);
      const auto [it, inserted] = ids.emplace(cell.id, plan->cells.size());
      if (!inserted) {
        ThrowBadValue(spec.file.string() + ": axes",
                      PointKey(points[p]).dump() + " and " +
                          PointKey(plan->cells[it->second].params).dump(),
                      "settings that differ: these two resolve to the same config (the same "
                      "cell twice)");
      }
      plan->cells.push_back(std::move(cell));
    }
  }
}

}  // namespace

Plan BuildPlan(const SweepSpec& spec, const std::string& mmh_version, const fs::path& workdir) {
  Plan plan;
  plan.spec = spec;
  plan.mmh_version = mmh_version;
  plan.workdir = workdir;
  plan.inputs = CommandInputs(spec);
  const Config base = BaseConfig(spec);
  AxisChecker(spec, base).CheckAll();
  plan.axes = AxesOf(spec);
  const std::vector<Point> points = ExpandPoints(spec);
  plan.points = static_cast<int>(points.size());
  AddCells(base, points, &plan);
  plan.cells_per_worker = spec.cells_per_worker > 0 ? spec.cells_per_worker
                          : PacksByDefault(spec.command) ? 0  // decided by the backend
                                                         : 1;
  return plan;
}

json PlanToJson(const Plan& plan) {
  json cells = json::array();
  for (const auto& c : plan.cells) {
    json params = json::array();
    for (const auto& [k, v] : c.params) params.push_back({k, v});
    json cell = {{"id", c.id}, {"point", c.point}, {"replicate", c.replicate}, {"params", params}};
    if (c.seed) cell["seed"] = *c.seed;
    cells.push_back(cell);
  }
  return {{"format", "mmh-sweep-plan-1"},
          {"mmh_version", plan.mmh_version},
          {"command", CommandName(plan.spec.command)},
          {"spec", NormalizedSpec(plan.spec)},
          {"spec_file", plan.spec.file.string()},
          {"workdir", plan.workdir.string()},
          {"inputs", plan.inputs},
          {"points", plan.points},
          {"cells_per_worker", plan.cells_per_worker},
          {"cells", cells}};
}

Plan PlanFromJson(const json& j, const fs::path& file) {
  try {
    if (j.at("format") != "mmh-sweep-plan-1") {
      ThrowBadValue(file.string() + ": format", j.at("format").dump(), "\"mmh-sweep-plan-1\"");
    }
    Plan plan;
    json spec = j.at("spec");
    spec.erase("config_file");
    plan.spec = ParseSpec(spec, j.at("spec_file").get<std::string>());
    plan.spec.json = spec;
    plan.mmh_version = j.at("mmh_version").get<std::string>();
    plan.workdir = j.at("workdir").get<std::string>();
    plan.inputs = j.at("inputs").get<std::vector<std::string>>();
    plan.points = j.at("points").get<int>();
    plan.cells_per_worker = j.at("cells_per_worker").get<int>();
    plan.axes = AxesOf(plan.spec);
    for (const auto& c : j.at("cells")) {
      Cell cell;
      cell.id = c.at("id").get<std::string>();
      cell.point = c.at("point").get<int>();
      cell.replicate = c.at("replicate").get<int>();
      for (const auto& kv : c.at("params")) cell.params.emplace_back(kv.at(0).get<std::string>(), kv.at(1));
      if (c.contains("seed")) cell.seed = c.at("seed").get<std::uint64_t>();
      plan.cells.push_back(std::move(cell));
    }
    return plan;
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": not a sweep plan mmh wrote (" + e.what() + ")");
  }
}

namespace {

// plan.json: through ParseJsonText (syntax errors and repeated keys name the file and line) with
// ReadTextFile's 1 GiB cap, not ReadJsonFile's 16 MiB: the plan of a sweep of 10^5 cells is larger.
json ReadPlanJson(const fs::path& file) { return ParseJsonText(ReadTextFile(file), file.string()); }

}  // namespace

fs::path CellConfigPath(const fs::path& dir, const Cell& cell) {
  return dir / "configs" / (cell.id + ".json");
}

namespace {

// WriteFileAtomically's temporary (NAME.tmp.PID.N) of a writer that was killed.
bool IsTemporary(const fs::path& file) {
  return file.filename().string().find(".tmp.") != std::string::npos;
}

// Whether `dir` holds only what WritePlan writes before plan.json: configs/ with cell configs
// (and temporaries of a killed writer). Such a folder is a sweep killed while writing its plan,
// and is continued: refusing it would leave the user a folder no rerun accepts.
bool OnlyAnUnfinishedPlan(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    if (IsTemporary(e.path()) && e.is_regular_file()) continue;
    if (e.path().filename() != "configs" || !e.is_directory()) return false;
  }
  if (!fs::exists(dir / "configs")) return true;
  for (const auto& e : fs::directory_iterator(dir / "configs")) {
    if (!e.is_regular_file() || (e.path().extension() != ".json" && !IsTemporary(e.path()))) {
      return false;
    }
  }
  return true;
}

}  // namespace

void WritePlan(const fs::path& dir, const Plan& plan) {
  const fs::path plan_file = dir / "plan.json";
  const json now = PlanToJson(plan);
  if (fs::exists(plan_file)) {
    const json earlier = ReadPlanJson(plan_file);
    if (!earlier.is_object()) {
      ThrowBadValue(plan_file.string(), "unreadable JSON", "the plan of an earlier mmh sweep");
    }
    json a = {{"spec", earlier.value("spec", json())},
              {"mmh_version", earlier.value("mmh_version", json())},
              {"command", earlier.value("command", json())},
              {"inputs", earlier.value("inputs", json())}};
    json b = {{"spec", now["spec"]},
              {"mmh_version", now["mmh_version"]},
              {"command", now["command"]},
              {"inputs", now["inputs"]}};
    const json patch = json::diff(a, b);
    if (!patch.empty()) {
      std::string keys;
      for (const auto& op : patch) {
        std::string key = op["path"].get<std::string>().substr(1);
        std::replace(key.begin(), key.end(), '/', '.');
        if (key.rfind("spec.", 0) == 0) key = key.substr(5);
        keys += (keys.empty() ? "" : ", ") + key;
      }
      throw InputError(dir.string() + " holds a sweep of another spec (" +
                       earlier.value("spec_file", std::string("?")) + "); keys that differ: " +
                       keys + ". Use another --out, or the same spec to continue that sweep");
    }
  } else if (fs::exists(dir) && !fs::is_empty(dir) && !OnlyAnUnfinishedPlan(dir)) {
    ThrowBadValue("--out " + dir.string(), "a non-empty folder without plan.json",
                  "a new or empty folder, or the folder of an earlier sweep of this spec");
  }
  const bool continued = fs::exists(plan_file);
  // What a killed `mmh sweep` left between a write and its rename. The plan and the configs are
  // written only by this command, the tables by its aggregation (here, or the Slurm job that a
  // rerun does not run beside); cells/, which workers on other hosts write, is not swept.
  for (const fs::path& folder : {dir, dir / "configs", dir / "plots"}) {
    RemoveStaleTemporaries(folder, /*subfolders=*/false);
  }
  EnsureDirectory(dir / "configs");
  for (const auto& cell : plan.cells) {
    // Without a plan.json, configs of a killed writer are not trusted: all are written again.
    const fs::path path = CellConfigPath(dir, cell);
    if (!continued || !fs::exists(path)) WriteFileAtomically(path, cell.config.dump(2) + "\n");
  }
  // Written last: a plan.json means every config beside it is in place.
  WriteFileAtomically(plan_file, now.dump(1) + "\n");
}

Plan ReadPlan(const fs::path& dir) {
  const fs::path file = dir / "plan.json";
  if (!fs::exists(file)) {
    ThrowBadValue(file.string(), "missing", "the folder of a sweep (mmh sweep --spec ... --out DIR)");
  }
  return PlanFromJson(ReadPlanJson(file), file);
}

}  // namespace mmh::sweep
