#include "calibrate/calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/rgbd_folder.h"
#include "core/text_parsing.h"
#include "study/simulated_study.h"
#include "sweep/cell_store.h"
#include "sweep/plan.h"

namespace mmh::calibrate {
namespace {

std::string Num(double value) { return FormatNumber(value); }

std::string Rounded(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", digits, value);
  return buffer;
}

int IndexOf(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// Reads a replicates.csv (study/simulated_study.h) into rows of values in `columns` order.
std::vector<std::vector<std::optional<double>>> ReadReplicates(
    const std::filesystem::path& file, const std::vector<std::string>& columns) {
  const std::string text = ReadTextFile(file);
  std::istringstream lines(text);
  std::string line;
  std::vector<int> column_of;  // file column -> index in columns (-1: not used)
  std::vector<std::vector<std::optional<double>>> rows;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    const std::string_view content = Trim(line);
    if (content.empty()) continue;
    const std::vector<std::string_view> fields = SplitCsvFields(content);
    if (column_of.empty()) {
      for (const auto& f : fields) column_of.push_back(IndexOf(columns, std::string(f)));
      for (const std::string& c : columns) {
        if (std::find(fields.begin(), fields.end(), c) == fields.end()) {
          ThrowBadValue(file.string() + ":1", "a header without the column '" + c + "'",
                        "the columns of replicates.csv of this mmh version");
        }
      }
      continue;
    }
    if (fields.size() != column_of.size()) {
      ThrowBadValue(file.string() + ":" + std::to_string(number),
                    std::to_string(fields.size()) + " fields",
                    std::to_string(column_of.size()) + " as in the header");
    }
    std::vector<std::optional<double>> row(columns.size());
    for (std::size_t f = 0; f < fields.size(); ++f) {
      if (column_of[f] < 0 || fields[f].empty()) continue;
      double value = 0;
      if (!ParseDouble(fields[f], &value) || !std::isfinite(value)) {
        ThrowBadValue(file.string() + ":" + std::to_string(number) + ", column '" +
                          columns[column_of[f]] + "'",
                      "'" + std::string(fields[f]) + "'", "a finite number or empty");
      }
      row[column_of[f]] = value;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

TargetCheck Check(const Target& target, const std::vector<double>& values) {
  TargetCheck c;
  c.target = target;
  c.samples = static_cast<int>(values.size());
  if (values.empty()) return c;
  c.median = Quantile(values, 0.5);
  c.q05 = Quantile(values, 0.05);
  c.q95 = Quantile(values, 0.95);
  double below = 0;
  for (double v : values) below += v < target.value ? 1.0 : (v == target.value ? 0.5 : 0.0);
  c.quantile = below / values.size();
  c.inside_central_90 = c.quantile >= 0.05 && c.quantile <= 0.95;
  return c;
}

constexpr std::pair<PpcDraws, const char*> kPpcDrawsNames[] = {
    {PpcDraws::kEstimate, "estimate"}, {PpcDraws::kPosterior, "posterior"}};

// The next round's sweep spec: this sweep's spec (as planned) with the sampled axes narrowed to
// `box`, a new sample seed, and optionally more points or studies per cell.
nlohmann::json NextRoundSpec(const nlohmann::json& spec, const std::filesystem::path& sweep_dir,
                             const std::vector<Parameter>& box, const NextRoundOptions& options) {
  nlohmann::json next = spec;
  nlohmann::json& samples = next["samples"];
  for (std::size_t j = 0; j < box.size(); ++j) {
    samples["axes"][j]["from"] = box[j].from;
    samples["axes"][j]["to"] = box[j].to;
  }
  samples["seed"] = samples.value("seed", std::uint64_t{1}) + 1;
  if (options.points > 0) samples["count"] = options.points;
  if (options.replicates > 0) {
    const std::string assignment = "study.replicates=" + std::to_string(options.replicates);
    nlohmann::json sets = nlohmann::json::array();
    if (next.contains("set")) {
      for (const auto& set : next["set"]) {
        if (!(set.is_string() && set.get<std::string>().starts_with("study.replicates="))) {
          sets.push_back(set);
        }
      }
    }
    sets.push_back(assignment);
    next["set"] = sets;
  }
  next["description"] =
      "Next calibration round, written by mmh calibrate from the sweep " + sweep_dir.string() +
      ": the prior narrowed to that round's accepted region (each parameter's accepted range "
      "widened by " + Num(options.margin) + " of it on each side, inside the previous prior). "
      "Previous description: " + spec.value("description", std::string());
  return next;
}

}  // namespace

std::span<const std::pair<PpcDraws, const char*>> EnumNames(PpcDraws) { return kPpcDrawsNames; }

void NextRoundOptions::Validate(const std::string& prefix) const {
  if (!(margin >= 0.0 && margin <= 10.0)) {
    ThrowBadValue(prefix + ".margin", FormatNumber(margin), "a share of the range in [0, 10]");
  }
  if (points < 0 || points > 1'000'000) {
    ThrowBadValue(prefix + ".points", std::to_string(points), "0 (as this sweep) or a count <= 1e6");
  }
  if (replicates < 0 || replicates > 100'000) {
    ThrowBadValue(prefix + ".replicates", std::to_string(replicates),
                  "0 (as this sweep) or a count <= 100000");
  }
}

void CalibrationOptions::Validate(const std::string& prefix) const {
  abc.Validate(prefix + ".abc");
  next_round.Validate(prefix + ".next_round");
  if (ppc_replicates < 0 || ppc_replicates > 100'000) {
    ThrowBadValue(prefix + ".ppc_replicates", std::to_string(ppc_replicates),
                  "a number of studies in [0, 100000]");
  }
  if (bootstrap < 0 || bootstrap > 100'000) {
    ThrowBadValue(prefix + ".bootstrap", std::to_string(bootstrap),
                  "a number of resamples in [0, 100000]");
  }
  if (digits < 1 || digits > 17) {
    ThrowBadValue(prefix + ".digits", std::to_string(digits), "an integer in [1, 17]");
  }
}

namespace {

// A calibration sweep: fast-fidelity studies over sampled axes (the prior), no grid.
void CheckCalibrationSweep(const sweep::Plan& plan, const std::string& where) {
  if (plan.spec.command != sweep::SweepCommand::kStudy) {
    ThrowBadValue(where + ": command", std::string("\"") + sweep::CommandName(plan.spec.command) + "\"",
                  "\"study\": a calibration sweep runs fast-fidelity studies");
  }
  if (plan.spec.samples.count == 0 || plan.spec.samples.axes.empty()) {
    ThrowBadValue(where + ": samples", "none",
                  "the parameters as sampled axes (random or latin_hypercube) over their prior "
                  "ranges");
  }
  if (!plan.spec.grid.empty()) {
    ThrowBadValue(where + ": grid", std::to_string(plan.spec.grid.size()) + " grid axes",
                  "none: every parameter a sampled axis (a grid is not a prior)");
  }
}

// Every replicate of every complete cell is a simulation at that cell's parameters.
void ReadSimulations(const sweep::Plan& plan, const std::filesystem::path& sweep_dir,
                     const std::string& where, CalibrationResult* result) {
  for (const sweep::Cell& cell : plan.cells) {
    const sweep::CellStatus status = sweep::ReadCellStatus(sweep_dir, cell.id);
    const std::filesystem::path file = sweep::CellDir(sweep_dir, cell.id) / "out" / "replicates.csv";
    if (status.state != sweep::CellState::kComplete || !std::filesystem::exists(file)) {
      ++result->incomplete_cells;
      continue;
    }
    ++result->cells;
    std::vector<double> params;
    for (const Parameter& p : result->parameters) {
      const auto it = std::find_if(cell.params.begin(), cell.params.end(),
                                   [&](const auto& kv) { return kv.first == p.key; });
      if (it == cell.params.end() || !it->second.is_number()) {
        ThrowBadValue(where + ": cell " + cell.id, "no number for " + p.key,
                      "a value of every sampled axis");
      }
      params.push_back(it->second.get<double>());
    }
    for (auto& row : ReadReplicates(file, result->statistics)) {
      result->simulations.push_back({params, std::move(row)});
      result->simulation_cell.push_back(result->cells - 1);
    }
  }
  if (result->cells == 0) {
    ThrowBadValue(sweep_dir.string(), "a sweep without complete cells",
                  "a finished sweep (mmh sweep status " + sweep_dir.string() + ")");
  }
}

// The values of statistic `k` over the given rows (missing values left out).
std::vector<double> ColumnValues(const std::vector<std::vector<std::optional<double>>>& rows,
                                 int k) {
  std::vector<double> values;
  for (const auto& row : rows) {
    if (row[k]) values.push_back(*row[k]);
  }
  return values;
}

// Rejection ABC on the fitted targets, the prior sensitivity, the estimate (posterior medians)
// and its Monte Carlo spread, and every target against the accepted simulations.
void FitPosterior(const Targets& targets, const CalibrationOptions& options,
                  const std::vector<double>& from, const std::vector<double>& to,
                  CalibrationResult* result) {
  std::vector<std::pair<int, double>> fit;
  for (const Target& t : targets.targets) {
    if (t.role == TargetRole::kFit) fit.push_back({IndexOf(result->statistics, t.statistic), t.value});
  }
  result->abc = RejectionAbc(result->simulations, fit, options.abc, from, to);
  result->sensitivity =
      PriorSensitivity(result->simulations, static_cast<int>(result->statistics.size()));
  for (const ParameterPosterior& p : result->abc.posterior) result->estimate.push_back(p.median);
  result->bootstrap_medians = BootstrapMedians(result->simulations, result->simulation_cell, fit,
                                               options.abc, from, to, options.bootstrap,
                                               options.bootstrap_seed);
  for (std::size_t j = 0; j < result->parameters.size() && !result->bootstrap_medians.empty(); ++j) {
    result->estimate_spread.push_back(SummarizeColumn(result->bootstrap_medians, j));
  }
  for (const Target& t : targets.targets) {
    const int k = IndexOf(result->statistics, t.statistic);
    std::vector<double> values;
    for (int i : result->abc.accepted) {
      if (result->simulations[i].values[k]) values.push_back(*result->simulations[i].values[k]);
    }
    result->accepted_checks.push_back(Check(t, values));
  }
}

// Posterior predictive check: new people and scorers (options.ppc_seed), at the rounded estimate
// or at the accepted draws in order (nearest first, cycling when there are fewer than studies).
void RunPredictiveCheck(const Config& config, const std::vector<double>& rounded_estimate,
                        const CalibrationOptions& options, const CalibrationProgress& progress,
                        CalibrationResult* result) {
  const study::StudyConfig study_config = study::StudyConfig::FromConfig(config);
  result->ppc_config = study_config.ToJson();
  result->ppc_draws = options.ppc_draws == PpcDraws::kPosterior ? "posterior" : "estimate";
  for (int r = 0; r < options.ppc_replicates; ++r) {
    std::vector<double> theta = rounded_estimate;
    study::StudyConfig draw_config = study_config;
    if (options.ppc_draws == PpcDraws::kPosterior) {
      theta = result->abc.accepted_params[r % result->abc.accepted_params.size()];
      Config draw = config;
      for (std::size_t j = 0; j < result->parameters.size(); ++j) {
        draw.Set(result->parameters[j].key + "=" + Rounded(theta[j], 17));
      }
      draw_config = study::StudyConfig::FromConfig(draw);
    }
    const study::SimulatedStudy s = study::RunSimulatedStudy(draw_config.ForReplicate(r), r);
    std::vector<std::optional<double>> row;
    for (const auto& statistic : study::ReplicateStatistics(s.analysis)) row.push_back(statistic.value);
    result->ppc_values.push_back(std::move(row));
    result->ppc_params.push_back(std::move(theta));
    if (progress) progress(r + 1, options.ppc_replicates);
  }
}

// Every target and every conclusion against the predictive studies.
void CheckPredictions(const Targets& targets, CalibrationResult* result) {
  for (const Target& t : targets.targets) {
    result->ppc.push_back(
        Check(t, ColumnValues(result->ppc_values, IndexOf(result->statistics, t.statistic))));
  }
  for (const Conclusion& c : targets.conclusions) {
    const int k = IndexOf(result->statistics, c.statistic);
    ConclusionCheck check;
    check.conclusion = c;
    for (const auto& row : result->ppc_values) {
      if (!row[k]) continue;
      ++check.replicates;
      check.agree += ((*row[k] < c.bound) == c.below) ? 1 : 0;
    }
    check.rate = check.replicates ? static_cast<double>(check.agree) / check.replicates : 0.0;
    result->conclusions.push_back(check);
  }
}

}  // namespace

CalibrationResult Calibrate(const std::filesystem::path& sweep_dir, const Targets& targets,
                            const CalibrationOptions& options,
                            const CalibrationProgress& progress) {
  options.Validate("calibration");
  const sweep::Plan plan = sweep::ReadPlan(sweep_dir);
  const std::string where = (sweep_dir / "plan.json").string();
  CheckCalibrationSweep(plan, where);
  CalibrationResult result;
  result.sweep_dir = sweep_dir;
  for (const sweep::SampledAxis& axis : plan.spec.samples.axes) {
    result.parameters.push_back({axis.key, axis.from, axis.to});
  }
  for (const auto& s : study::ReplicateStatistics(study::StudyAnalysis{})) {
    result.statistics.push_back(s.name);
  }
  ReadSimulations(plan, sweep_dir, where, &result);
  std::vector<double> from, to;
  for (const Parameter& p : result.parameters) from.push_back(p.from), to.push_back(p.to);
  FitPosterior(targets, options, from, to, &result);

  // The calibrated config: the estimate, rounded, as config sections.
  Config calibrated;
  Config config = Config::Load(sweep::CellConfigPath(sweep_dir, plan.cells.front()));
  std::vector<double> rounded_estimate;
  for (std::size_t j = 0; j < result.parameters.size(); ++j) {
    const std::string value = Rounded(result.estimate[j], options.digits);
    rounded_estimate.push_back(std::stod(value));
    const std::string assignment = result.parameters[j].key + "=" + value;
    calibrated.Set(assignment);
    config.Set(assignment);
  }
  result.calibrated_config = calibrated.root();

  // The next round's prior and spec.
  const auto box = NarrowedPrior(result.abc.accepted_params, from, to, options.next_round.margin);
  for (std::size_t j = 0; j < result.parameters.size(); ++j) {
    result.next_prior.push_back({result.parameters[j].key, box[j].first, box[j].second});
  }
  result.next_round_spec =
      NextRoundSpec(plan.spec.json, sweep_dir, result.next_prior, options.next_round);

  config.Set("population.seed=" + std::to_string(options.ppc_seed));
  config.Set("study.seed=" + std::to_string(options.ppc_seed));
  config.Set("run.metrics=false");
  RunPredictiveCheck(config, rounded_estimate, options, progress, &result);
  if (options.ppc_replicates > 0) CheckPredictions(targets, &result);
  return result;
}

namespace {

// parameters.csv: the estimate and its uncertainty; returns calibration.json's "parameters".
nlohmann::json WriteParameters(const std::filesystem::path& dir, const CalibrationResult& result) {
  std::string csv = "parameter,prior_from,prior_to,estimate,posterior_mean,posterior_sd,q05,q95\n";
  nlohmann::json params = nlohmann::json::array();
  for (std::size_t j = 0; j < result.parameters.size(); ++j) {
    const Parameter& p = result.parameters[j];
    const ParameterPosterior& post = result.abc.posterior[j];
    csv += p.key + "," + Num(p.from) + "," + Num(p.to) + "," + Num(post.median) + "," +
           Num(post.mean) + "," + Num(post.sd) + "," + Num(post.q05) + "," + Num(post.q95) + "\n";
    params.push_back({{"key", p.key}, {"prior", {p.from, p.to}}, {"estimate", post.median},
                      {"mean", post.mean}, {"sd", post.sd}, {"q05", post.q05}, {"q95", post.q95}});
  }
  WriteFileAtomically(dir / "parameters.csv", csv);
  return params;
}

// stability.csv: how far the estimate moves over bootstrap resamples of the cells (also into
// each parameter's "bootstrap" of calibration.json).
void WriteStability(const std::filesystem::path& dir, const CalibrationResult& result,
                    nlohmann::json* params) {
  if (result.estimate_spread.empty()) return;
  std::string csv = "parameter,estimate,posterior_sd,bootstrap_draws,bootstrap_sd,bootstrap_q05,"
                    "bootstrap_q95,bootstrap_sd_over_posterior_sd\n";
  for (std::size_t j = 0; j < result.parameters.size(); ++j) {
    const ParameterPosterior& post = result.abc.posterior[j];
    const ParameterPosterior& mc = result.estimate_spread[j];
    csv += result.parameters[j].key + "," + Num(post.median) + "," + Num(post.sd) + "," +
           std::to_string(result.bootstrap_medians.size()) + "," + Num(mc.sd) + "," +
           Num(mc.q05) + "," + Num(mc.q95) + "," +
           (post.sd > 0 ? Num(mc.sd / post.sd) : std::string()) + "\n";
    (*params)[j]["bootstrap"] = {{"sd", mc.sd}, {"q05", mc.q05}, {"q95", mc.q95}};
  }
  WriteFileAtomically(dir / "stability.csv", csv);
}

// posterior.csv: the accepted simulations (distance, parameters as sampled and as adjusted; the
// same when calibration.abc.regression_adjustment is off).
void WritePosterior(const std::filesystem::path& dir, const CalibrationResult& result) {
  std::string csv = "simulation,distance";
  for (const Parameter& p : result.parameters) csv += "," + p.key;
  for (const Parameter& p : result.parameters) csv += "," + p.key + ".adjusted";
  csv += "\n";
  for (std::size_t r = 0; r < result.abc.accepted.size(); ++r) {
    const int i = result.abc.accepted[r];
    csv += std::to_string(i) + "," + Num(result.abc.distances[i]);
    for (double v : result.simulations[i].params) csv += "," + Num(v);
    for (double v : result.abc.accepted_params[r]) csv += "," + Num(v);
    csv += "\n";
  }
  WriteFileAtomically(dir / "posterior.csv", csv);
}

// identification.csv: standardised sensitivity of every target statistic to every parameter;
// returns calibration.json's "identification".
nlohmann::json WriteIdentification(const std::filesystem::path& dir,
                                   const CalibrationResult& result, const Targets& targets) {
  std::string csv = "statistic,role,samples,r_squared";
  for (const Parameter& p : result.parameters) csv += "," + p.key;
  csv += "\n";
  nlohmann::json identification = nlohmann::json::array();
  for (const Target& t : targets.targets) {
    const int k = IndexOf(result.statistics, t.statistic);
    csv += t.statistic + "," + RoleName(t.role) + "," +
           std::to_string(result.sensitivity.samples[k]) + "," +
           Num(result.sensitivity.r_squared[k]);
    nlohmann::json row = {{"statistic", t.statistic}, {"r_squared", result.sensitivity.r_squared[k]}};
    for (std::size_t j = 0; j < result.parameters.size(); ++j) {
      csv += "," + Num(result.sensitivity.coefficients[k][j]);
      row["coefficients"][result.parameters[j].key] = result.sensitivity.coefficients[k][j];
    }
    csv += "\n";
    identification.push_back(row);
  }
  WriteFileAtomically(dir / "identification.csv", csv);
  return identification;
}

// targets.csv: every reported number against the accepted and the predictive distributions;
// returns calibration.json's "targets".
nlohmann::json WriteTargets(const std::filesystem::path& dir, const CalibrationResult& result,
                            const Targets& targets) {
  std::string csv =
      "statistic,role,paper,accepted_median,accepted_q05,accepted_q95,ppc_samples,ppc_median,"
      "ppc_q05,ppc_q95,ppc_quantile,inside_central_90\n";
  nlohmann::json checks = nlohmann::json::array();
  for (std::size_t i = 0; i < targets.targets.size(); ++i) {
    const Target& t = targets.targets[i];
    const TargetCheck& a = result.accepted_checks[i];
    csv += t.statistic + "," + RoleName(t.role) + "," + Num(t.value) + "," + Num(a.median) + "," +
           Num(a.q05) + "," + Num(a.q95);
    nlohmann::json j = {{"statistic", t.statistic}, {"role", RoleName(t.role)}, {"paper", t.value},
                        {"accepted", {{"median", a.median}, {"q05", a.q05}, {"q95", a.q95}}}};
    if (i < result.ppc.size()) {
      const TargetCheck& p = result.ppc[i];
      csv += "," + std::to_string(p.samples) + "," + Num(p.median) + "," + Num(p.q05) + "," +
             Num(p.q95) + "," + Num(p.quantile) + "," + (p.inside_central_90 ? "1" : "0");
      j["ppc"] = {{"samples", p.samples}, {"median", p.median},     {"q05", p.q05},
                  {"q95", p.q95},         {"quantile", p.quantile}, {"inside_central_90", p.inside_central_90}};
    } else {
      csv += ",,,,,,";
    }
    csv += "\n";
    checks.push_back(j);
  }
  WriteFileAtomically(dir / "targets.csv", csv);
  return checks;
}

// conclusions.csv: the paper's conclusions against the predictive studies; returns
// calibration.json's "conclusions".
nlohmann::json WriteConclusions(const std::filesystem::path& dir, const CalibrationResult& result) {
  std::string csv = "conclusion,statistic,bound,below,role,replicates,agree,rate\n";
  nlohmann::json conclusions = nlohmann::json::array();
  for (const ConclusionCheck& c : result.conclusions) {
    csv += c.conclusion.id + "," + c.conclusion.statistic + "," + Num(c.conclusion.bound) + "," +
           (c.conclusion.below ? "1" : "0") + "," + RoleName(c.conclusion.role) + "," +
           std::to_string(c.replicates) + "," + std::to_string(c.agree) + "," + Num(c.rate) + "\n";
    conclusions.push_back({{"id", c.conclusion.id}, {"description", c.conclusion.description},
                           {"role", RoleName(c.conclusion.role)}, {"replicates", c.replicates},
                           {"agree", c.agree}, {"rate", c.rate}});
  }
  WriteFileAtomically(dir / "conclusions.csv", csv);
  return conclusions;
}

// ppc_replicates.csv: each predictive study's parameters and statistics.
void WritePredictiveReplicates(const std::filesystem::path& dir, const CalibrationResult& result) {
  std::string csv = "replicate";
  for (const Parameter& p : result.parameters) csv += "," + p.key;
  for (const std::string& s : result.statistics) csv += "," + s;
  csv += "\n";
  for (std::size_t r = 0; r < result.ppc_values.size(); ++r) {
    csv += std::to_string(r);
    for (double v : result.ppc_params[r]) csv += "," + Num(v);
    for (const auto& v : result.ppc_values[r]) csv += "," + (v ? Num(*v) : std::string());
    csv += "\n";
  }
  WriteFileAtomically(dir / "ppc_replicates.csv", csv);
}

// report.md: the tables a reader needs first.
std::string ReportMarkdown(const CalibrationResult& result) {
  std::ostringstream md;
  md << "# Calibration of the simulated people\n\n"
     << result.simulations.size() << " simulated studies (" << result.cells << " cells of "
     << result.sweep_dir.string() << "), " << result.abc.accepted.size()
     << " accepted (distance <= " << Num(result.abc.epsilon) << ").\n\n"
     << "| parameter | prior | estimate (posterior median) | central 90 % | estimate's Monte Carlo "
        "sd (bootstrap of the cells) |\n|---|---|---|---|---|\n";
  for (std::size_t j2 = 0; j2 < result.parameters.size(); ++j2) {
    const auto& p = result.parameters[j2];
    const auto& post = result.abc.posterior[j2];
    md << "| " << p.key << " | " << Num(p.from) << "–" << Num(p.to) << " | "
       << Rounded(post.median, 3) << " | " << Rounded(post.q05, 3) << "–" << Rounded(post.q95, 3)
       << " | "
       << (j2 < result.estimate_spread.size() ? Rounded(result.estimate_spread[j2].sd, 2) : "")
       << " |\n";
  }
  md << "\nNext round (next_round.json): the prior narrowed to the accepted region:";
  for (const Parameter& p : result.next_prior) {
    md << " " << p.key << " " << Rounded(p.from, 3) << "–" << Rounded(p.to, 3) << ";";
  }
  md << "\n\nPosterior predictive check: " << result.ppc_values.size() << " new studies "
     << (result.ppc_draws == "posterior"
             ? "at draws from the posterior (the accepted θ: posterior.csv's .adjusted columns)"
             : "at the rounded estimate")
     << ".\n";
  md << "\n| statistic | role | paper | predictive median (90 %) | quantile of the paper's |\n"
        "|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < result.ppc.size(); ++i) {
    const auto& p = result.ppc[i];
    md << "| " << p.target.statistic << " | " << RoleName(p.target.role) << " | "
       << Num(p.target.value) << " | " << Rounded(p.median, 3) << " (" << Rounded(p.q05, 3) << "–"
       << Rounded(p.q95, 3) << ") | " << Rounded(p.quantile, 3)
       << (p.inside_central_90 ? "" : " (outside)") << " |\n";
  }
  if (!result.conclusions.empty()) {
    md << "\n| conclusion | role | replicates agreeing with the paper |\n|---|---|---|\n";
    for (const auto& c : result.conclusions) {
      md << "| " << c.conclusion.id << " | " << RoleName(c.conclusion.role) << " | " << c.agree
         << " / " << c.replicates << " = " << Rounded(c.rate, 3) << " |\n";
    }
  }
  return md.str();
}

}  // namespace

void WriteCalibration(const std::filesystem::path& out, const CalibrationResult& result,
                      const Targets& targets, const nlohmann::json& provenance) {
  StagedFolder staged(out);
  const std::filesystem::path& dir = staged.staging();
  nlohmann::json params = WriteParameters(dir, result);
  WriteStability(dir, result, &params);
  WritePosterior(dir, result);
  const nlohmann::json identification = WriteIdentification(dir, result, targets);
  const nlohmann::json checks = WriteTargets(dir, result, targets);
  const nlohmann::json conclusions = WriteConclusions(dir, result);
  WritePredictiveReplicates(dir, result);
  WriteFileAtomically(dir / "calibrated.json", result.calibrated_config.dump(2) + "\n");
  WriteFileAtomically(dir / "config.resolved.json", result.ppc_config.dump(2) + "\n");
  WriteFileAtomically(dir / "next_round.json", result.next_round_spec.dump(2) + "\n");

  nlohmann::json j;
  j["sweep"] = result.sweep_dir.string();
  j["targets_file"] = targets.file.string();
  j["cells"] = result.cells;
  j["incomplete_cells"] = result.incomplete_cells;
  j["simulations"] = result.simulations.size();
  j["accepted"] = result.abc.accepted.size();
  j["epsilon"] = result.abc.epsilon;
  j["parameters"] = params;
  j["targets"] = checks;
  j["conclusions"] = conclusions;
  j["identification"] = identification;
  j["calibrated"] = result.calibrated_config;
  j["ppc_draws"] = result.ppc_draws;
  nlohmann::json next_prior = nlohmann::json::array();
  for (const Parameter& p : result.next_prior) {
    next_prior.push_back({{"key", p.key}, {"prior", {p.from, p.to}}});
  }
  j["next_round_prior"] = next_prior;
  WriteFileAtomically(dir / "calibration.json", j.dump(2) + "\n");
  WriteFileAtomically(dir / "report.md", ReportMarkdown(result));
  WriteFileAtomically(dir / "run.json", provenance.dump(2) + "\n");
  staged.Commit();
}

}  // namespace mmh::calibrate
