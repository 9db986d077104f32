// `mmh calibrate`: the simulated people's free parameters calibrated to the paper's reported
// numbers (docs/calibration.md). Input: a finished sweep of fast-fidelity `study` cells whose
// sampled axes are the parameters (configs/sweeps/calibrate_people.json, run with `mmh sweep`
// locally or on Slurm), and a targets file. Every replicate of every cell is one simulation of
// the approximate Bayesian computation (calibrate/abc.h) on the fit targets; the estimate is the
// posterior median; a posterior predictive check runs `ppc_replicates` new studies at the estimate
// and places every reported number, fitted and held out, in its simulated distribution.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "calibrate/abc.h"
#include "calibrate/targets.h"

namespace mmh::calibrate {

// Where the posterior predictive studies take the people's parameters from.
enum class PpcDraws {
  kEstimate,   // every study at the rounded estimate (the calibrated defaults)
  kPosterior,  // study r at the r-th accepted (adjusted) θ, cycling: parameter uncertainty included
};
std::span<const std::pair<PpcDraws, const char*>> EnumNames(PpcDraws);

// The second round's sweep spec (next_round.json): the prior narrowed by NarrowedPrior.
struct NextRoundOptions {
  double margin = 0.1;  // on each side, times the accepted range
  int points = 0;       // samples.count of the next sweep; 0: this sweep's
  int replicates = 0;   // studies per cell (study.replicates); 0: this sweep's

  template <class V>
  void VisitFields(V& v) {
    v("margin", margin);
    v("points", points);
    v("replicates", replicates);
  }
  void Validate(const std::string& prefix) const;
};

// Section "calibration" of `mmh calibrate --set`.
struct CalibrationOptions {
  AbcOptions abc;
  // Posterior predictive studies at the estimate (the issue asks for at least 200); 0: none.
  int ppc_replicates = 200;
  // population.seed and study.seed of the predictive studies (new people, new scorers: not the
  // sweep's, so the check is out of sample).
  std::uint64_t ppc_seed = 2014;
  // The estimate only, or draws from the posterior (the predictive distribution proper, wider).
  PpcDraws ppc_draws = PpcDraws::kPosterior;
  // Bootstrap resamples of the sweep's cells for the estimate's Monte Carlo error (stability.csv;
  // BootstrapMedians); 0: none. About 2 ms each for 2 400 simulations.
  int bootstrap = 200;
  std::uint64_t bootstrap_seed = 2014;
  NextRoundOptions next_round;
  // Significant digits of the calibrated values written as the config (calibrated.json).
  int digits = 3;

  template <class V>
  void VisitFields(V& v) {
    v("abc", abc);
    v("ppc_replicates", ppc_replicates);
    v("ppc_seed", ppc_seed);
    v("ppc_draws", ppc_draws);
    v("bootstrap", bootstrap);
    v("bootstrap_seed", bootstrap_seed);
    v("next_round", next_round);
    v("digits", digits);
  }
  void Validate(const std::string& prefix) const;
};

struct Parameter {
  std::string key;  // config key, e.g. "viewer.judgement_noise"
  double from = 0.0;
  double to = 1.0;
};

// A reported number against its simulated distribution (prior over the sweep, or predictive at
// the estimate).
struct TargetCheck {
  Target target;
  int samples = 0;
  double median = 0.0;
  double q05 = 0.0;
  double q95 = 0.0;
  // Share of the simulated values below the paper's number (ties count half): its quantile.
  double quantile = 0.0;
  bool inside_central_90 = false;  // 0.05 <= quantile <= 0.95
};

struct ConclusionCheck {
  Conclusion conclusion;
  int replicates = 0;  // replicates where the statistic was computed
  int agree = 0;       // of them, with the paper's conclusion
  double rate = 0.0;
};

struct CalibrationResult {
  std::filesystem::path sweep_dir;
  std::vector<Parameter> parameters;
  std::vector<std::string> statistics;  // replicates.csv columns, the order of Simulation::values
  int cells = 0;                        // complete cells read
  int incomplete_cells = 0;             // missing or failed (not used)
  std::vector<Simulation> simulations;  // one per replicate of every complete cell
  std::vector<int> simulation_cell;     // the complete cell (0-based) of each simulation
  AbcResult abc;
  Sensitivity sensitivity;
  std::vector<double> estimate;  // posterior median of each parameter
  // The estimate's Monte Carlo error: the medians over bootstrap resamples of the cells.
  std::vector<std::vector<double>> bootstrap_medians;  // [draw][parameter]
  std::vector<ParameterPosterior> estimate_spread;     // per parameter, over the draws
  std::vector<TargetCheck> accepted_checks;  // the accepted simulations against the targets
  std::vector<TargetCheck> ppc;              // the predictive studies against the targets
  std::vector<ConclusionCheck> conclusions;  // in the predictive studies
  std::vector<std::vector<std::optional<double>>> ppc_values;  // [replicate][statistic]
  std::vector<std::vector<double>> ppc_params;                 // [replicate][parameter]
  std::string ppc_draws;                                       // "estimate" or "posterior"
  // The next round: the narrowed prior and the sweep spec over it (next_round.json).
  std::vector<Parameter> next_prior;
  nlohmann::json next_round_spec;
  nlohmann::json calibrated_config;  // the estimate as config sections (rounded)
  nlohmann::json ppc_config;         // the resolved study config of the predictive studies
};

// progress(done, total) over the predictive studies.
using CalibrationProgress = std::function<void(int done, int total)>;

// Reads the sweep (its plan and every complete cell's out/replicates.csv), fits, and runs the
// predictive check. InputError when the sweep is not of `study` cells with sampled axes, a target
// names a parameter's statistic that no cell computed, or no cell is complete.
CalibrationResult Calibrate(const std::filesystem::path& sweep_dir, const Targets& targets,
                            const CalibrationOptions& options,
                            const CalibrationProgress& progress = {});

// Writes calibration.json, parameters.csv, posterior.csv, identification.csv, targets.csv,
// conclusions.csv, ppc_replicates.csv, calibrated.json and report.md into `out` (complete or
// absent).
void WriteCalibration(const std::filesystem::path& out, const CalibrationResult& result,
                      const Targets& targets, const nlohmann::json& provenance);

}  // namespace mmh::calibrate
