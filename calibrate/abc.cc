#include "calibrate/abc.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "stats/descriptive.h"

namespace mmh::calibrate {

void AbcOptions::Validate(const std::string& prefix) const {
  if (!(accept_fraction > 0.0 && accept_fraction <= 1.0)) {
    ThrowBadValue(prefix + ".accept_fraction", FormatNumber(accept_fraction), "a share in (0, 1]");
  }
}

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const double h = (values.size() - 1) * q;
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(values.size() - 1, lo + 1);
  return values[lo] + (h - lo) * (values[hi] - values[lo]);
}

ParameterPosterior SummarizeColumn(const std::vector<std::vector<double>>& draws, std::size_t j) {
  std::vector<double> values;
  for (const auto& theta : draws) values.push_back(theta[j]);
  ParameterPosterior p;
  p.median = Quantile(values, 0.5);
  p.q05 = Quantile(values, 0.05);
  p.q95 = Quantile(values, 0.95);
  p.mean = stats::Mean(values);
  p.sd = values.size() > 1 ? std::sqrt(stats::Variance(values)) : 0;
  return p;
}

AbcResult RejectionAbc(const std::vector<Simulation>& simulations,
                       const std::vector<std::pair<int, double>>& fit, const AbcOptions& options,
                       const std::vector<double>& prior_from, const std::vector<double>& prior_to) {
  options.Validate("calibration.abc");
  AbcResult result;
  const int n = static_cast<int>(simulations.size());
  // Scales: the MAD of each fit statistic over the simulations that have it.
  for (const auto& [k, observed] : fit) {
    std::vector<double> values;
    for (const Simulation& s : simulations) {
      if (s.values[k]) values.push_back(*s.values[k]);
    }
    const double median = Quantile(values, 0.5);
    for (double& v : values) v = std::abs(v - median);
    double mad = 1.4826 * Quantile(values, 0.5);
    // A statistic that barely varies (e.g. a count at its bound) gets its sd instead; a constant
    // one cannot discriminate and weighs nothing.
    if (!(mad > 0)) {
      std::vector<double> present;
      for (const Simulation& s : simulations) {
        if (s.values[k]) present.push_back(*s.values[k]);
      }
      mad = present.size() > 1 ? std::sqrt(stats::Variance(present)) : 0;
    }
    result.scales.push_back(mad);
  }
  result.distances.assign(n, NAN);
  std::vector<int> usable;
  for (int i = 0; i < n; ++i) {
    double d2 = 0;
    bool ok = true;
    for (std::size_t f = 0; f < fit.size(); ++f) {
      const auto& value = simulations[i].values[fit[f].first];
      if (!value) {
        ok = false;
        break;
      }
      if (result.scales[f] > 0) {
        const double z = (*value - fit[f].second) / result.scales[f];
        d2 += z * z;
      }
    }
    if (!ok) continue;
    result.distances[i] = std::sqrt(d2);
    usable.push_back(i);
  }
  if (usable.size() < 2) {
    ThrowBadValue("calibration", std::to_string(usable.size()) + " simulations with every fit statistic",
                  "at least 2 (run more sweep cells)");
  }
  // Nearest first; ties by index, so the result does not depend on anything but the inputs.
  std::stable_sort(usable.begin(), usable.end(),
                   [&](int a, int b) { return result.distances[a] < result.distances[b]; });
  const int accept = std::max(
      2, static_cast<int>(std::lround(options.accept_fraction * static_cast<double>(usable.size()))));
  result.accepted.assign(usable.begin(), usable.begin() + std::min<int>(accept, usable.size()));
  result.epsilon = result.distances[result.accepted.back()];
  const int parameters = static_cast<int>(simulations.front().params.size());
  for (int i : result.accepted) result.accepted_params.push_back(simulations[i].params);
  const int m = static_cast<int>(result.accepted.size());
  const int f = static_cast<int>(fit.size());
  if (options.regression_adjustment && result.epsilon > 0 && m > f + 1) {
    // Weighted least squares of θ_j on the scaled summaries (s − t)/MAD among the accepted.
    Eigen::MatrixXd x(m, f + 1);
    Eigen::VectorXd w(m);
    for (int r = 0; r < m; ++r) {
      const int i = result.accepted[r];
      const double u = result.distances[i] / result.epsilon;
      w(r) = std::max(0.0, 1.0 - u * u);
      x(r, 0) = 1.0;
      for (int k = 0; k < f; ++k) {
        const double scale = result.scales[k] > 0 ? result.scales[k] : 1.0;
        x(r, k + 1) = (*simulations[i].values[fit[k].first] - fit[k].second) / scale;
      }
    }
    const Eigen::VectorXd sw = w.array().sqrt();
    const Eigen::MatrixXd xw = sw.asDiagonal() * x;
    const auto qr = xw.colPivHouseholderQr();
    for (int j = 0; j < parameters; ++j) {
      Eigen::VectorXd y(m);
      for (int r = 0; r < m; ++r) y(r) = simulations[result.accepted[r]].params[j];
      const Eigen::VectorXd beta = qr.solve(sw.asDiagonal() * y);
      for (int r = 0; r < m; ++r) {
        double adjusted = y(r) - x.row(r).tail(f).dot(beta.tail(f));
        if (j < static_cast<int>(prior_from.size())) {
          adjusted = std::clamp(adjusted, std::min(prior_from[j], prior_to[j]),
                                std::max(prior_from[j], prior_to[j]));
        }
        result.accepted_params[r][j] = adjusted;
      }
    }
  }
  for (int j = 0; j < parameters; ++j) {
    result.posterior.push_back(SummarizeColumn(result.accepted_params, j));
  }
  return result;
}

std::vector<std::vector<double>> BootstrapMedians(
    const std::vector<Simulation>& simulations, const std::vector<int>& cell_of,
    const std::vector<std::pair<int, double>>& fit, const AbcOptions& options,
    const std::vector<double>& prior_from, const std::vector<double>& prior_to, int draws,
    std::uint64_t seed) {
  if (cell_of.size() != simulations.size()) {
    ThrowBadValue("calibration bootstrap", std::to_string(cell_of.size()) + " cell indices",
                  "one per simulation (" + std::to_string(simulations.size()) + ")");
  }
  int cells = 0;
  for (int c : cell_of) cells = std::max(cells, c + 1);
  std::vector<std::vector<int>> members(cells);
  for (std::size_t i = 0; i < cell_of.size(); ++i) members[cell_of[i]].push_back(static_cast<int>(i));
  // SplitMix64 (Steele, Lea & Flood 2014): portable, unlike the standard distributions.
  std::uint64_t state = seed;
  const auto next = [&state] {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  std::vector<std::vector<double>> medians;
  for (int b = 0; b < draws; ++b) {
    std::vector<Simulation> resample;
    resample.reserve(simulations.size());
    for (int c = 0; c < cells; ++c) {
      const auto pick = static_cast<std::size_t>(next() % static_cast<std::uint64_t>(cells));
      for (int i : members[pick]) resample.push_back(simulations[i]);
    }
    const AbcResult r = RejectionAbc(resample, fit, options, prior_from, prior_to);
    std::vector<double> m;
    for (const ParameterPosterior& p : r.posterior) m.push_back(p.median);
    medians.push_back(std::move(m));
  }
  return medians;
}

std::vector<std::pair<double, double>> NarrowedPrior(
    const std::vector<std::vector<double>>& accepted_params, const std::vector<double>& prior_from,
    const std::vector<double>& prior_to, double margin) {
  if (!(margin >= 0.0) || !std::isfinite(margin)) {
    ThrowBadValue("calibration.next_round.margin", FormatNumber(margin), "a share >= 0");
  }
  std::vector<std::pair<double, double>> box;
  for (std::size_t j = 0; j < prior_from.size(); ++j) {
    const double lo_prior = std::min(prior_from[j], prior_to[j]);
    const double hi_prior = std::max(prior_from[j], prior_to[j]);
    double lo = hi_prior, hi = lo_prior;
    for (const auto& theta : accepted_params) {
      lo = std::min(lo, theta[j]);
      hi = std::max(hi, theta[j]);
    }
    if (accepted_params.empty() || !(hi > lo)) {
      box.emplace_back(prior_from[j], prior_to[j]);
      continue;
    }
    const double pad = margin * (hi - lo);
    box.emplace_back(std::max(lo_prior, lo - pad), std::min(hi_prior, hi + pad));
  }
  return box;
}

Sensitivity PriorSensitivity(const std::vector<Simulation>& simulations, int statistics) {
  Sensitivity out;
  const int parameters = simulations.empty() ? 0 : static_cast<int>(simulations.front().params.size());
  out.coefficients.assign(statistics, std::vector<double>(parameters, NAN));
  out.r_squared.assign(statistics, NAN);
  out.samples.assign(statistics, 0);
  for (int k = 0; k < statistics; ++k) {
    std::vector<int> rows;
    for (int i = 0; i < static_cast<int>(simulations.size()); ++i) {
      if (simulations[i].values[k]) rows.push_back(i);
    }
    out.samples[k] = static_cast<int>(rows.size());
    if (static_cast<int>(rows.size()) <= parameters + 1) continue;
    const int m = static_cast<int>(rows.size());
    Eigen::MatrixXd x(m, parameters + 1);
    Eigen::VectorXd y(m);
    for (int r = 0; r < m; ++r) {
      x(r, 0) = 1.0;
      for (int j = 0; j < parameters; ++j) x(r, j + 1) = simulations[rows[r]].params[j];
      y(r) = *simulations[rows[r]].values[k];
    }
    const double y_mean = y.mean();
    const double y_sd = std::sqrt((y.array() - y_mean).square().sum() / (m - 1));
    if (!(y_sd > 0)) continue;
    const Eigen::VectorXd beta = x.colPivHouseholderQr().solve(y);
    const Eigen::VectorXd residual = y - x * beta;
    out.r_squared[k] = 1.0 - residual.squaredNorm() / (y.array() - y_mean).square().sum();
    for (int j = 0; j < parameters; ++j) {
      const Eigen::VectorXd col = x.col(j + 1);
      const double sd = std::sqrt((col.array() - col.mean()).square().sum() / (m - 1));
      out.coefficients[k][j] = beta(j + 1) * sd / y_sd;
    }
  }
  return out;
}

}  // namespace mmh::calibrate
