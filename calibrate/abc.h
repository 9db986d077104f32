// Approximate Bayesian computation by rejection (Pritchard et al. 1999; Beaumont, Zhang & Balding
// 2002) on simulated studies: every simulation is one replicate study at a parameter vector θ
// drawn from the prior (the sweep's Latin-hypercube sample over the parameters' ranges), with its
// summary statistics s. With the paper's numbers t as the observed summaries,
//
//   d(θ) = sqrt( Σ_k ((s_k − t_k) / MAD_k)² )      over the fit targets k,
//
// MAD_k the median absolute deviation of s_k over all simulations (× 1.4826, so that it estimates
// a standard deviation), and the simulations with the smallest `accept_fraction` of distances are
// a sample of the approximate posterior p(θ | d ≤ ε). With `regression_adjustment` (off by
// default: AbcOptions says why) each accepted θ_i is corrected for how far its summaries fell
// from the observed ones (Beaumont, Zhang & Balding 2002, eq. 4): θ_i* = θ_i − β̂ᵀ (s_i − t), β̂
// from the weighted least-squares regression of θ on s among the accepted, Epanechnikov weights
// 1 − (d_i/ε)²; θ_i* is kept in the prior's range. The adjustment removes the part of the
// posterior's spread that ε lets through.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace mmh::calibrate {

struct Simulation {
  std::vector<double> params;                 // θ, #parameters
  std::vector<std::optional<double>> values;  // s, #statistics (nullopt: not computed)
};

// Options of RejectionAbc.
struct AbcOptions {
  double accept_fraction = 0.05;  // share of the simulations accepted, in (0, 1]
  // Off by default: the adjustment fits 1 + #fit statistics coefficients per parameter (11 for
  // paper_targets_with_h3.json) to the accepted studies, about 120 of a 2 400-study sweep, and its
  // noise moved the posterior median by as much as the posterior's own sd between bootstrap
  // resamples of the cells (stability.csv: 0.85-1.32 x in two rounds), against 0.24-0.42 x
  // without it (docs/calibration.md, "A second round"). Beaumont, Zhang & Balding (2002) fitted
  // it to thousands of accepted simulations; at these sweep sizes plain rejection (Pritchard et
  // al. 1999) gives a stable estimate at the price of a posterior widened by ε. Turn it on for
  // sweeps with many more accepted studies than fit statistics.
  bool regression_adjustment = false;

  template <class V>
  void VisitFields(V& v) {
    v("accept_fraction", accept_fraction);
    v("regression_adjustment", regression_adjustment);
  }
  void Validate(const std::string& prefix) const;
};

struct ParameterPosterior {
  double median = 0.0;
  double mean = 0.0;
  double sd = 0.0;
  double q05 = 0.0;  // 5 % and 95 % quantiles: the central 90 % credible interval
  double q95 = 0.0;
};

struct AbcResult {
  std::vector<double> scales;           // MAD_k of each fit statistic
  std::vector<double> distances;        // d of every simulation (NaN: a fit statistic missing)
  std::vector<int> accepted;            // indices of the accepted simulations, nearest first
  double epsilon = 0.0;                 // the largest accepted distance
  // θ of the accepted (after the regression adjustment, when on), [accepted][parameter].
  std::vector<std::vector<double>> accepted_params;
  std::vector<ParameterPosterior> posterior;  // #parameters
};

// Median, mean, sd and 5 %/95 % quantiles of column j of `draws` ([draw][parameter]).
ParameterPosterior SummarizeColumn(const std::vector<std::vector<double>>& draws, std::size_t j);

// `fit` lists the statistics (indices into Simulation::values) and their observed values.
// Simulations missing a fit statistic are never accepted. InputError when fewer than 2 usable
// simulations remain or the options are invalid.
// `prior_from` / `prior_to` bound each parameter (the adjusted values are clamped to them; empty:
// unbounded).
AbcResult RejectionAbc(const std::vector<Simulation>& simulations,
                       const std::vector<std::pair<int, double>>& fit, const AbcOptions& options,
                       const std::vector<double>& prior_from = {},
                       const std::vector<double>& prior_to = {});

// Which summaries identify which parameters: the standardised coefficients of the linear
// regression of each statistic on all parameters over every simulation (prior predictive),
// β_kj · sd(θ_j) / sd(s_k), and its R². A parameter no statistic moves is not identified.
struct Sensitivity {
  std::vector<std::vector<double>> coefficients;  // [statistic][parameter]
  std::vector<double> r_squared;                  // [statistic]
  std::vector<int> samples;                       // simulations with the statistic
};
Sensitivity PriorSensitivity(const std::vector<Simulation>& simulations, int statistics);

// How much the estimate (the posterior median) moves when the sweep is run again: the ABC
// repeated on `draws` bootstrap resamples of the sweep's cells (cells drawn with replacement, each
// with all its simulations, so replicates at one θ stay together; `cell_of[i]` is simulation i's
// cell, 0-based and dense). Returns [draw][parameter] medians. The spread of a parameter's medians
// is the Monte Carlo error of its estimate: small against the posterior's width, the estimate is
// stable. The resamples come from a 64-bit SplitMix generator seeded with `seed`, so the same
// inputs give the same draws on every platform.
std::vector<std::vector<double>> BootstrapMedians(
    const std::vector<Simulation>& simulations, const std::vector<int>& cell_of,
    const std::vector<std::pair<int, double>>& fit, const AbcOptions& options,
    const std::vector<double>& prior_from, const std::vector<double>& prior_to, int draws,
    std::uint64_t seed);

// The prior of a second, narrower round (sequential ABC with a truncated prior): per parameter,
// the range of the accepted (adjusted) θ widened by `margin` times that range on each side and
// kept inside the current prior [from, to]. The second round samples uniformly over it, so its
// posterior is the first round's posterior restricted to the box, which is the same posterior as
// long as the box holds all of its mass (the margin's job). A parameter whose accepted values
// are all equal keeps its current range. Returns {from, to} per parameter.
std::vector<std::pair<double, double>> NarrowedPrior(
    const std::vector<std::vector<double>>& accepted_params, const std::vector<double>& prior_from,
    const std::vector<double>& prior_to, double margin);

// The q-quantile of `values` (type 7 of R's quantile(): linear between order statistics).
double Quantile(std::vector<double> values, double q);

}  // namespace mmh::calibrate
