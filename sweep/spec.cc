#include "sweep/spec.h"

#include <cmath>
#include <map>
#include <set>

#include "core/config.h"
#include "core/error.h"
#include "core/options.h"
#include "core/text_parsing.h"

namespace mmh::sweep {
namespace {

using nlohmann::json;

// Reads one JSON object of the spec: every key must be one of `known`; messages name the file and
// the object's path in the spec ("axes[1]").
class SpecObject {
 public:
  SpecObject(const json& object, std::string where, const std::string& file,
             std::vector<std::string> known)
      : object_(object), where_(std::move(where)), file_(file) {
    if (!object.is_object()) Fail("", object, "an object");
    for (auto it = object.begin(); it != object.end(); ++it) {
      bool found = false;
      for (const auto& k : known) found = found || k == it.key();
      if (found) continue;
      const std::string suggestion = options_internal::SuggestName(it.key(), known);
      throw InputError(file_ + ": key '" + Path(it.key()) + "' is unknown" +
                       (suggestion.empty() ? "" : " (did you mean '" + suggestion + "'?)") +
                       "; known keys here: " + options_internal::JoinNames(known));
    }
  }

  bool Has(const std::string& key) const { return object_.contains(key); }
  const json& At(const std::string& key) const { return object_.at(key); }

  [[noreturn]] void Fail(const std::string& key, const json& value,
                         const std::string& expected) const {
    ThrowBadValue(file_ + ": " + Path(key), value.dump(), expected);
  }
  std::string Path(const std::string& key) const {
    if (key.empty()) return where_.empty() ? "(top level)" : where_;
    return where_.empty() ? key : where_ + "." + key;
  }

  std::string String(const std::string& key, const std::string& fallback) const {
    if (!Has(key)) return fallback;
    if (!At(key).is_string() || At(key).get<std::string>().empty()) {
      Fail(key, At(key), "a non-empty string");
    }
    return At(key).get<std::string>();
  }
  double Number(const std::string& key) const {
    if (!Has(key)) Fail(key, json(), "a number (required)");
    if (!At(key).is_number() || !std::isfinite(At(key).get<double>())) {
      Fail(key, At(key), "a finite number");
    }
    return At(key).get<double>();
  }
  long long Integer(const std::string& key, long long fallback, long long min, long long max) const {
    if (!Has(key)) return fallback;
    const json& v = At(key);
    if (!v.is_number_integer() || v.get<long long>() < min || v.get<long long>() > max) {
      Fail(key, v, "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    return v.get<long long>();
  }
  bool Bool(const std::string& key, bool fallback) const {
    if (!Has(key)) return fallback;
    if (!At(key).is_boolean()) Fail(key, At(key), "true or false");
    return At(key).get<bool>();
  }
  std::vector<std::string> Strings(const std::string& key) const {
    std::vector<std::string> out;
    if (!Has(key)) return out;
    if (!At(key).is_array()) Fail(key, At(key), "an array of strings");
    for (const json& v : At(key)) {
      if (!v.is_string()) Fail(key, v, "an array of strings");
      out.push_back(v.get<std::string>());
    }
    return out;
  }
  template <class E>
  E Choice(const std::string& key, E fallback,
           const std::vector<std::pair<E, const char*>>& names) const {
    if (!Has(key)) return fallback;
    std::vector<std::string> all;
    for (const auto& [e, name] : names) {
      all.emplace_back(name);
      if (At(key).is_string() && At(key).get<std::string>() == name) return e;
    }
    Fail(key, At(key), "one of " + options_internal::JoinNames(all));
  }

 private:
  const json& object_;
  std::string where_;
  const std::string& file_;
};

std::string Indexed(const std::string& name, std::size_t i) {
  return name + "[" + std::to_string(i) + "]";
}

const std::vector<std::pair<AxisScale, const char*>> kScales = {{AxisScale::kLinear, "linear"},
                                                                 {AxisScale::kLog, "log"}};
const std::vector<std::pair<Statistic, const char*>> kStatistics = {
    {Statistic::kMean, "mean"}, {Statistic::kSd, "sd"},   {Statistic::kCi95, "ci95"},
    {Statistic::kMin, "min"},   {Statistic::kMax, "max"}, {Statistic::kMedian, "median"}};

GridAxis ReadGridAxis(const json& j, const std::string& where, const std::string& file) {
  const SpecObject o(j, where, file, {"key", "values", "lin", "log", "integer"});
  GridAxis axis;
  axis.key = o.String("key", "");
  if (axis.key.empty()) o.Fail("key", json(), "the config key the axis varies (required)");
  const int forms = o.Has("values") + o.Has("lin") + o.Has("log");
  if (forms != 1) {
    o.Fail("", j, "exactly one of 'values' (a list), 'lin' or 'log' ({from, to, count})");
  }
  const std::string axis_where = where + " (" + axis.key + ")";
  if (o.Has("values")) {
    if (o.Has("integer")) o.Fail("integer", o.At("integer"), "'integer' only with 'lin' or 'log'");
    const json& values = o.At("values");
    if (!values.is_array() || values.empty()) {
      ThrowBadValue(file + ": " + axis_where + ".values", values.dump(),
                    "a non-empty list of values");
    }
    std::set<std::string> seen;
    for (const json& v : values) {
      if (!seen.insert(v.dump()).second) {
        ThrowBadValue(file + ": " + axis_where + ".values", v.dump(),
                      "each value once (a repeated value would run the same cells twice)");
      }
      axis.values.push_back(v);
    }
    return axis;
  }
  const bool log = o.Has("log");
  axis.scale = log ? AxisScale::kLog : AxisScale::kLinear;
  const SpecObject range(o.At(log ? "log" : "lin"), axis_where + (log ? ".log" : ".lin"), file,
                         {"from", "to", "count"});
  const double from = range.Number("from"), to = range.Number("to");
  const int count = static_cast<int>(range.Integer("count", -1, 1, 100000));
  if (count < 0) range.Fail("count", json(), "an integer >= 1 (required)");
  if (log && (from <= 0 || to <= 0)) {
    range.Fail(from <= 0 ? "from" : "to", from <= 0 ? from : to,
               "a number > 0 (a log range)");
  }
  if (count > 1 && from == to) range.Fail("to", to, "a number other than 'from' when count > 1");
  const bool integer = o.Bool("integer", false);
  std::vector<double> values = ExpandRange(from, to, count, axis.scale);
  std::set<double> seen;
  for (double v : values) {
    if (integer) {
      v = std::round(v);
      if (!seen.insert(v).second) continue;  // a log range of integers repeats small values
      axis.values.push_back(static_cast<long long>(v));
    } else {
      axis.values.push_back(v);
    }
  }
  return axis;
}

SampleSet ReadSamples(const json& j, const std::string& file) {
  const SpecObject o(j, "samples", file, {"method", "count", "seed", "axes"});
  SampleSet set;
  set.method = o.Choice("method", SampleMethod::kLatinHypercube,
                        {{SampleMethod::kRandom, "random"},
                         {SampleMethod::kLatinHypercube, "latin_hypercube"}});
  set.count = static_cast<int>(o.Integer("count", -1, 1, 1000000));
  if (set.count < 0) o.Fail("count", json(), "an integer >= 1 (required)");
  set.seed = static_cast<std::uint64_t>(o.Integer("seed", 1, 0, (1ll << 53)));
  if (!o.Has("axes") || !o.At("axes").is_array() || o.At("axes").empty()) {
    o.Fail("axes", o.Has("axes") ? o.At("axes") : json(), "a non-empty list of sampled axes");
  }
  for (std::size_t i = 0; i < o.At("axes").size(); ++i) {
    const std::string where = Indexed("samples.axes", i);
    const SpecObject a(o.At("axes")[i], where, file, {"key", "from", "to", "scale", "integer"});
    SampledAxis axis;
    axis.key = a.String("key", "");
    if (axis.key.empty()) a.Fail("key", json(), "the config key the axis varies (required)");
    const SpecObject named(o.At("axes")[i], where + " (" + axis.key + ")", file,
                           {"key", "from", "to", "scale", "integer"});
    axis.from = named.Number("from");
    axis.to = named.Number("to");
    axis.scale = named.Choice("scale", AxisScale::kLinear, kScales);
    axis.integer = named.Bool("integer", false);
    if (!(axis.from < axis.to)) named.Fail("to", axis.to, "a number greater than 'from'");
    if (axis.scale == AxisScale::kLog && axis.from <= 0) {
      named.Fail("from", axis.from, "a number > 0 (a log scale)");
    }
    set.axes.push_back(axis);
  }
  return set;
}

}  // namespace

const char* CommandName(SweepCommand command) {
  switch (command) {
    case SweepCommand::kRun: return "run";
    case SweepCommand::kStudy: return "study";
    case SweepCommand::kCompose: return "compose";
    case SweepCommand::kTrack: return "track";
  }
  return "?";
}

const char* StatisticName(Statistic statistic) {
  for (const auto& [s, name] : kStatistics) {
    if (s == statistic) return name;
  }
  return "?";
}

std::vector<double> ExpandRange(double from, double to, int count, AxisScale scale) {
  std::vector<double> values;
  for (int i = 0; i < count; ++i) {
    const double u = count == 1 ? 0.0 : static_cast<double>(i) / (count - 1);
    double v = scale == AxisScale::kLog
                   ? std::exp(std::log(from) + u * (std::log(to) - std::log(from)))
                   : from + u * (to - from);
    // 12 significant digits: the ends exactly, 0.1 + 0.2 as 0.3, 10^1.5 as 31.6227766017, so
    // that the values read well in tables and configs (and mean the same on every platform).
    if (v != 0) {
      const double scale10 = std::pow(10.0, 11 - std::floor(std::log10(std::abs(v))));
      v = std::round(v * scale10) / scale10;
    }
    values.push_back(i == 0 ? from : i == count - 1 ? to : v);
  }
  return values;
}

namespace {

// The base config: a file (read now, so that a missing one is an error before anything runs) or
// an inline object.
void ReadBaseConfig(const SpecObject& o, SweepSpec* spec) {
  if (!o.Has("config")) return;
  const json& c = o.At("config");
  if (c.is_string()) {
    spec->base_config_file = c.get<std::string>();
    spec->base_config = Config::Load(spec->base_config_file).root();
  } else if (c.is_object()) {
    spec->base_config = c;
  } else {
    o.Fail("config", c, "a config file (path) or an inline config object");
  }
}

// The grid axes and the samples; at least one axis.
void ReadAxes(const SpecObject& o, const std::string& file, SweepSpec* spec) {
  if (o.Has("axes")) {
    const json& axes = o.At("axes");
    if (!axes.is_array()) o.Fail("axes", axes, "a list of axes");
    for (std::size_t i = 0; i < axes.size(); ++i) {
      spec->grid.push_back(ReadGridAxis(axes[i], Indexed("axes", i), file));
    }
  }
  if (o.Has("samples")) spec->samples = ReadSamples(o.At("samples"), file);
  if (spec->grid.empty() && spec->samples.count == 0) {
    o.Fail("axes", o.Has("axes") ? o.At("axes") : json(),
           "at least one axis ('axes' or 'samples'): a sweep over nothing is one plain run");
  }
}

// The config keys the sweep varies: each on one axis only (the replicates' seed key included).
class VariedKeys {
 public:
  explicit VariedKeys(const std::string& file) : file_(file) {}
  void Add(const std::string& key, const std::string& where) {
    const auto [it, inserted] = keys_.emplace(key, where);
    if (!inserted) {
      ThrowBadValue(file_ + ": " + where, "\"" + key + "\"",
                    "each config key on one axis only (" + it->second + " varies it too)");
    }
  }

 private:
  const std::string& file_;
  std::map<std::string, std::string> keys_;  // key -> where it is varied
};

// The replicates; run cells are seeded through population.seed, study cells through
// population.seed and study.seed, unless the spec names its own keys (seed_key: a key or a list).
void ReadReplicates(const SpecObject& o, const std::string& file, VariedKeys* keys,
                    SweepSpec* spec) {
  Replicates& replicates = spec->replicates;
  bool named = false;
  if (o.Has("replicates")) {
    const SpecObject r(o.At("replicates"), "replicates", file, {"count", "seed_key", "seeds", "seed"});
    replicates.count = static_cast<int>(r.Integer("count", 1, 1, 100000));
    if (r.Has("seed_key")) {
      named = true;
      const json& key = r.At("seed_key");
      if (key.is_string() && !key.get<std::string>().empty()) {
        replicates.seed_keys = {key.get<std::string>()};
      } else if (key.is_array() && !key.empty()) {
        for (const json& k : key) {
          if (!k.is_string() || k.get<std::string>().empty()) {
            r.Fail("seed_key", key, "a config key or a non-empty list of config keys");
          }
          replicates.seed_keys.push_back(k.get<std::string>());
        }
      } else {
        r.Fail("seed_key", key, "a config key or a non-empty list of config keys");
      }
    }
    replicates.scheme = r.Choice("seeds", SeedScheme::kPerCell,
                                 {{SeedScheme::kPerCell, "per_cell"},
                                  {SeedScheme::kCommon, "common"}});
    replicates.seed = static_cast<std::uint64_t>(r.Integer("seed", 1, 0, (1ll << 53)));
  }
  if (!named && spec->command == SweepCommand::kRun) replicates.seed_keys = {"population.seed"};
  if (!named && spec->command == SweepCommand::kStudy) {
    replicates.seed_keys = {"population.seed", "study.seed"};
  }
  if (replicates.count > 1 && replicates.seed_keys.empty()) {
    ThrowBadValue(file + ": replicates.count", std::to_string(replicates.count),
                  "1 for `mmh " + std::string(CommandName(spec->command)) +
                      "` (it has no seed; or name one in replicates.seed_key)");
  }
  // A seeded key is set in every cell (Seeded), so an axis on it would be overwritten.
  if (Seeded(replicates)) {
    for (const std::string& key : replicates.seed_keys) keys->Add(key, "replicates.seed_key");
  }
}

// metrics[i]: a CSV column name (not in `names`, then added), a file in the command's output
// folder, a dotted key and the statistics of summary.csv (mean, sd, ci95 unless given).
Metric ReadMetric(const json& j, std::size_t i, const std::string& file,
                  std::set<std::string>* names) {
  const SpecObject m(j, Indexed("metrics", i), file, {"name", "file", "key", "summary"});
  Metric metric;
  metric.name = m.String("name", "");
  metric.file = m.String("file", "");
  metric.key = m.String("key", "");
  if (metric.name.empty() || metric.file.empty() || metric.key.empty()) {
    m.Fail("", j, "{\"name\": column, \"file\": output file, \"key\": dotted path}");
  }
  for (char c : metric.name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      m.Fail("name", metric.name, "letters, digits and '_' (a CSV column)");
    }
  }
  if (!names->insert(metric.name).second) m.Fail("name", metric.name, "a name used once");
  if (metric.file.find("..") != std::string::npos || metric.file.front() == '/') {
    m.Fail("file", metric.file, "a path inside the command's output folder");
  }
  if (!m.Has("summary")) {
    metric.statistics = {Statistic::kMean, Statistic::kSd, Statistic::kCi95};
    return metric;
  }
  if (!m.At("summary").is_array() || m.At("summary").empty()) {
    m.Fail("summary", m.At("summary"), "a non-empty list of mean, sd, ci95, min, max, median");
  }
  for (std::size_t s = 0; s < m.At("summary").size(); ++s) {
    const json wrapper = {{"s", m.At("summary")[s]}};
    const SpecObject one(wrapper, m.Path("summary") + "[" + std::to_string(s) + "]", file, {"s"});
    metric.statistics.push_back(one.Choice("s", Statistic::kMean, kStatistics));
  }
  return metric;
}

void ReadMetrics(const SpecObject& o, const std::string& file, SweepSpec* spec) {
  if (!o.Has("metrics") || !o.At("metrics").is_array() || o.At("metrics").empty()) {
    o.Fail("metrics", o.Has("metrics") ? o.At("metrics") : json(),
           "a non-empty list of metrics ({name, file, key})");
  }
  std::set<std::string> names;
  for (std::size_t i = 0; i < o.At("metrics").size(); ++i) {
    spec->metrics.push_back(ReadMetric(o.At("metrics")[i], i, file, &names));
  }
}

SlurmOptions ReadSlurm(const json& j, const std::string& file) {
  const SpecObject s(j, "slurm", file,
                     {"partition", "time", "throttle", "max_array_size", "cells_per_task",
                      "sbatch_args"});
  SlurmOptions slurm;
  slurm.partition = s.String("partition", "");
  slurm.time_limit = s.String("time", "");
  slurm.throttle = static_cast<int>(s.Integer("throttle", 0, 0, 1000000));
  slurm.max_array_size = static_cast<int>(s.Integer("max_array_size", 0, 0, 4000001));
  if (slurm.max_array_size == 1) s.Fail("max_array_size", 1, "0 (ask Slurm) or >= 2");
  slurm.cells_per_task = static_cast<int>(s.Integer("cells_per_task", 0, 0, 100000));
  slurm.sbatch_args = s.Strings("sbatch_args");
  return slurm;
}

}  // namespace

SweepSpec ParseSpec(const json& j, const std::filesystem::path& file_path) {
  const std::string file = file_path.string();
  const SpecObject o(j, "", file,
                     {"command", "description", "config", "set", "inputs", "axes", "samples",
                      "replicates", "metrics", "cells_per_worker", "slurm"});
  SweepSpec spec;
  spec.file = file_path;
  spec.json = j;
  if (!o.Has("command")) o.Fail("command", json(), "one of run, study, compose, track (required)");
  spec.command = o.Choice("command", SweepCommand::kRun,
                          {{SweepCommand::kRun, "run"},
                           {SweepCommand::kStudy, "study"},
                           {SweepCommand::kCompose, "compose"},
                           {SweepCommand::kTrack, "track"}});
  spec.description = o.Has("description") ? o.String("description", "") : "";
  ReadBaseConfig(o, &spec);
  spec.sets = o.Strings("set");
  if (o.Has("inputs")) {
    if (!o.At("inputs").is_object()) o.Fail("inputs", o.At("inputs"), "an object");
    spec.inputs = o.At("inputs");
  }
  ReadAxes(o, file, &spec);
  VariedKeys keys(file);
  for (std::size_t i = 0; i < spec.grid.size(); ++i) {
    keys.Add(spec.grid[i].key, Indexed("axes", i) + ".key");
  }
  for (std::size_t i = 0; i < spec.samples.axes.size(); ++i) {
    keys.Add(spec.samples.axes[i].key, Indexed("samples.axes", i) + ".key");
  }
  ReadReplicates(o, file, &keys, &spec);
  ReadMetrics(o, file, &spec);
  spec.cells_per_worker = static_cast<int>(o.Integer("cells_per_worker", 0, 0, 100000));
  if (o.Has("slurm")) spec.slurm = ReadSlurm(o.At("slurm"), file);
  return spec;
}

SweepSpec LoadSpec(const std::filesystem::path& file, const std::vector<std::string>& sets) {
  Config config = Config::Load(file);  // names the file, line and column of a JSON error
  for (const auto& set : sets) config.Set(set);
  return ParseSpec(config.root(), file);
}

}  // namespace mmh::sweep
