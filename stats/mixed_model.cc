#include "stats/mixed_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"
#include "stats/htest.h"

namespace mmh::stats {
namespace {

namespace bm = boost::math;

// The data in the form the REML algebra needs. X has one row per observation: 1 (intercept) and
// the indicators of levels 1..k-1 (treatment coding, level 0 the reference; R's default).
struct Design {
  std::size_t n = 0;  // observations
  std::size_t m = 0;  // groups
  std::size_t p = 0;  // fixed-effect columns = levels
  std::span<const int> group;
  std::span<const int> level;
  std::span<const double> y;
  Eigen::VectorXd group_size;  // n_i, #groups
  Eigen::MatrixXd group_x;     // row i: sum of the X rows of group i, #groups by p
  Eigen::MatrixXd xtx;         // X'X, p by p
  Eigen::VectorXd xty;         // X'y, p
  Eigen::VectorXd group_y;     // sum of y per group

  double X(std::size_t obs, std::size_t column) const {
    return column == 0 ? 1.0 : (level[obs] == static_cast<int>(column) ? 1.0 : 0.0);
  }
};

// Everything about the profiled REML criterion at one psi = theta^2 (docs/statistics.md):
//   V = I + psi Z Z', V^-1 = I - sum_i c_i 1_i 1_i' with c_i = psi / (1 + n_i psi),
//   M = X'V^-1 X, beta = M^-1 X'V^-1 y, e = y - X beta, r2 = e'V^-1 e,
//   d(psi) = log|V| + log|M| + (N - p)(1 + log(2 pi r2 / (N - p)))   (lme4's REML deviance),
//   d'(psi) = tr(S) - (N - p) |s|^2 / r2, S = Z'PZ = D - W M^-1 W', s = Z'P y,
// where D = diag(n_i / (1 + n_i psi)), W = Z'V^-1 X (row i: x_i / (1 + n_i psi)).
struct Evaluation {
  double psi = 0.0;
  Eigen::MatrixXd m_inverse;  // M^-1, p by p
  Eigen::VectorXd beta;
  Eigen::VectorXd residual;        // e, per observation
  Eigen::VectorXd group_residual;  // sum of e per group
  Eigen::MatrixXd w;               // #groups by p
  Eigen::VectorXd s;               // #groups
  Eigen::VectorXd d_diag;          // D = diag(n_i / (1 + n_i psi))
  double r2 = 0.0;
  double criterion = 0.0;
  double score = 0.0;
};

Evaluation Evaluate(const Design& d, double psi) {
  Evaluation ev;
  ev.psi = psi;
  const Eigen::Index p = static_cast<Eigen::Index>(d.p);
  const Eigen::Index m = static_cast<Eigen::Index>(d.m);
  Eigen::VectorXd c(m);
  Eigen::VectorXd inv(m);  // 1 / (1 + n_i psi)
  for (Eigen::Index i = 0; i < m; ++i) {
    inv(i) = 1.0 / (1.0 + d.group_size(i) * psi);
    c(i) = psi * inv(i);
  }
  Eigen::MatrixXd m_matrix = d.xtx;
  Eigen::VectorXd rhs = d.xty;
  for (Eigen::Index i = 0; i < m; ++i) {
    m_matrix.noalias() -= c(i) * d.group_x.row(i).transpose() * d.group_x.row(i);
    rhs.noalias() -= c(i) * d.group_y(i) * d.group_x.row(i).transpose();
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(m_matrix);
  ev.beta = llt.solve(rhs);
  ev.m_inverse = llt.solve(Eigen::MatrixXd::Identity(p, p));
  ev.residual.resize(static_cast<Eigen::Index>(d.n));
  ev.group_residual = Eigen::VectorXd::Zero(m);
  for (std::size_t j = 0; j < d.n; ++j) {
    double fit = ev.beta(0);
    if (d.level[j] > 0) fit += ev.beta(d.level[j]);
    ev.residual(j) = d.y[j] - fit;
    ev.group_residual(d.group[j]) += ev.residual(j);
  }
  // r2 = e'V^-1 e as a sum of non-negative terms, sum_j (e_j - c_i E_i)^2 + sum_i psi (inv_i
  // E_i)^2 with E_i the group sum of e (the same value as e'e - sum c_i E_i^2, without its
  // cancellation).
  ev.r2 = 0.0;
  for (std::size_t j = 0; j < d.n; ++j) {
    const double v = ev.residual(j) - c(d.group[j]) * ev.group_residual(d.group[j]);
    ev.r2 += v * v;
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    const double v = inv(i) * ev.group_residual(i);
    ev.r2 += psi * v * v;
  }
  const double residual_df = static_cast<double>(d.n - d.p);
  double log_det_v = 0.0;
  for (Eigen::Index i = 0; i < m; ++i) log_det_v += std::log1p(d.group_size(i) * psi);
  double log_det_m = 0.0;
  for (Eigen::Index i = 0; i < p; ++i) log_det_m += 2.0 * std::log(llt.matrixL()(i, i));
  ev.criterion = log_det_v + log_det_m +
                 residual_df * (1.0 + std::log(2.0 * std::numbers::pi * ev.r2 / residual_df));

  ev.w = d.group_x;
  for (Eigen::Index i = 0; i < m; ++i) ev.w.row(i) *= inv(i);
  ev.s = ev.group_residual.cwiseProduct(inv);
  ev.d_diag = d.group_size.cwiseProduct(inv);
  double trace_s = ev.d_diag.sum();
  trace_s -= (ev.m_inverse * (ev.w.transpose() * ev.w)).trace();
  ev.score = trace_s - residual_df * ev.s.squaredNorm() / ev.r2;
  return ev;
}

// Root of the score in [a, b] (score(a) < 0 <= score(b)) by bisection down to adjacent doubles.
double BisectScore(const Design& d, double a, double b, int* evaluations) {
  for (int iteration = 0; iteration < 400; ++iteration) {
    const double mid = 0.5 * (a + b);
    if (!(mid > a && mid < b)) break;
    ++*evaluations;
    if (Evaluate(d, mid).score < 0.0) {
      a = mid;
    } else {
      b = mid;
    }
  }
  // The end whose score is closer to zero.
  const double sa = std::abs(Evaluate(d, a).score);
  const double sb = std::abs(Evaluate(d, b).score);
  *evaluations += 2;
  return sa < sb ? a : b;
}

// lmerTest's doolittle(): the unit lower-triangular factor of the LU decomposition of `x`
// without pivoting, entries below eps = 1e-6 set to 0 (as lmerTest does).
Eigen::MatrixXd DoolittleL(const Eigen::MatrixXd& x) {
  const double eps = 1e-6;
  const Eigen::Index n = x.rows();
  Eigen::MatrixXd l = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      u(i, j) = x(i, j);
      for (Eigen::Index k = 0; k < i; ++k) u(i, j) -= l(i, k) * u(k, j);
    }
    for (Eigen::Index j = i + 1; j < n; ++j) {
      l(j, i) = x(j, i);
      for (Eigen::Index k = 0; k < i; ++k) l(j, i) -= l(j, k) * u(k, i);
      l(j, i) = std::abs(u(i, i)) < eps ? 0.0 : l(j, i) / u(i, i);
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      if (std::abs(l(i, j)) < eps) l(i, j) = 0.0;
    }
  }
  return l;
}

// lmerTest's get_Fstat_ddf: the denominator df of an F built from q one-dimensional t tests with
// Satterthwaite df nu_m (Fai & Cornelius 1996): 2E / (E - q), E = sum nu / (nu - 2).
double CombineDf(const std::vector<double>& nu) {
  if (nu.size() == 1) return nu[0];
  bool all_equal = true;
  for (std::size_t i = 1; i < nu.size(); ++i)
    all_equal = all_equal && std::abs(nu[i] - nu[i - 1]) < 1e-8;
  if (all_equal) {
    double sum = 0.0;
    for (double v : nu) sum += v;
    return sum / static_cast<double>(nu.size());
  }
  double e = 0.0;
  for (double v : nu) {
    if (v <= 2.0) return 2.0;
    e += v / (v - 2.0);
  }
  return 2.0 * e / (e - static_cast<double>(nu.size()));
}

double FUpperTail(double f, double num_df, double den_df) {
  if (!std::isfinite(den_df)) {
    return bm::cdf(bm::complement(bm::chi_squared_distribution<double>(num_df), f * num_df));
  }
  return bm::cdf(bm::complement(bm::fisher_f_distribution<double>(num_df, den_df), f));
}

FTest MakeFTest(double f, double num_df, double den_df, double sum_sq) {
  FTest t;
  t.f = f;
  t.num_df = num_df;
  t.den_df = den_df;
  t.p_value = FUpperTail(f, num_df, den_df);
  t.sum_sq = sum_sq;
  t.mean_sq = sum_sq / num_df;
  t.partial_eta_squared = f * num_df / (f * num_df + den_df);
  return t;
}

std::string Describe(const FTest& t) {
  return "F(" + FormatNumber(t.num_df) + ", " + FormatNumber(t.den_df) +
         ") = " + FormatNumber(t.f) + ", p = " + FormatNumber(t.p_value);
}

}  // namespace

void MixedModelOptions::Validate(const std::string& prefix) const {
  RequirePositive(hessian_tolerance, prefix + ".hessian_tolerance");
  RequireConfidenceLevel(conf_level, prefix + ".conf_level");
  if (grid_points_per_decade < 1 || grid_points_per_decade > 100) {
    ThrowBadValue(prefix + ".grid_points_per_decade", std::to_string(grid_points_per_decade),
                  "an integer in [1, 100]");
  }
}

nlohmann::json FTest::ToJson() const {
  return {{"f", f},
          {"num_df", num_df},
          {"den_df", FiniteOrNull(den_df)},
          {"p_value", p_value},
          {"sum_sq", sum_sq},
          {"mean_sq", mean_sq},
          {"partial_eta_squared", partial_eta_squared}};
}

nlohmann::json FixedEffect::ToJson() const {
  return {{"name", name},
          {"estimate", estimate},
          {"standard_error", standard_error},
          {"df", FiniteOrNull(df)},
          {"t", t},
          {"p_value", p_value},
          {"conf_int", conf_int.ToJson()}};
}

nlohmann::json MixedModelSummary::ToJson() const {
  return {{"observations", observations},
          {"groups", groups},
          {"levels", levels},
          {"balanced", balanced},
          {"score_evaluations", score_evaluations},
          {"warnings", warnings}};
}

nlohmann::json MixedModelResult::ToJson() const {
  nlohmann::json j;
  j["model"] = "score ~ take + (1 | animator), REML; F test with Satterthwaite df (lmerTest)";
  j["theta"] = theta;
  j["sigma"] = sigma;
  j["group_variance"] = group_variance;
  j["residual_variance"] = residual_variance;
  j["icc"] = icc;
  j["boundary"] = boundary;
  j["reml_criterion"] = reml_criterion;
  j["beta"] = std::vector<double>(beta.data(), beta.data() + beta.size());
  nlohmann::json cov = nlohmann::json::array();
  for (Eigen::Index i = 0; i < beta_covariance.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index k = 0; k < beta_covariance.cols(); ++k) row.push_back(beta_covariance(i, k));
    cov.push_back(row);
  }
  j["beta_covariance"] = cov;
  nlohmann::json effects = nlohmann::json::array();
  for (const auto& e : fixed_effects) effects.push_back(e.ToJson());
  j["fixed_effects"] = effects;
  j["direction_df"] = direction_df;
  j["take_test"] = take_test.ToJson();
  j["rm_anova"] = rm_anova ? rm_anova->ToJson() : nlohmann::json(nullptr);
  j["agrees_with_rm_anova"] = agrees_with_rm_anova;
  j["random_effects"] = random_effects;
  j["summary"] = summary.ToJson();
  return j;
}

namespace {

// The data as the REML algebra needs it, checked: InputError for anything lme4 would refuse.
// *balanced: every group has every level exactly once.
Design MakeDesign(std::span<const int> group, std::span<const int> level,
                  std::span<const double> y, bool* balanced) {
  if (group.size() != y.size() || level.size() != y.size()) {
    ThrowBadValue("mixed model data",
                  std::to_string(y.size()) + " scores, " + std::to_string(group.size()) +
                      " group indices, " + std::to_string(level.size()) + " level indices",
                  "one group and one level index per score");
  }
  RequireAllFinite(y, "mixed model scores");
  Design d;
  d.n = y.size();
  d.group = group;
  d.level = level;
  d.y = y;
  int max_group = -1;
  int max_level = -1;
  for (std::size_t j = 0; j < d.n; ++j) {
    if (group[j] < 0) ThrowBadValue("mixed model group index", std::to_string(group[j]), ">= 0");
    if (level[j] < 0) ThrowBadValue("mixed model level index", std::to_string(level[j]), ">= 0");
    max_group = std::max(max_group, group[j]);
    max_level = std::max(max_level, level[j]);
  }
  d.m = static_cast<std::size_t>(max_group + 1);
  d.p = static_cast<std::size_t>(max_level + 1);
  if (d.m < 2 || d.p < 2) {
    ThrowBadValue("mixed model data",
                  std::to_string(d.m) + " groups and " + std::to_string(d.p) + " levels",
                  "at least 2 groups (animators) and 2 levels (takes)");
  }
  if (d.n <= d.m) {
    ThrowBadValue("mixed model data",
                  std::to_string(d.n) + " observations for " + std::to_string(d.m) + " groups",
                  "more observations than groups (lme4: the number of levels of a grouping "
                  "factor must be < the number of observations)");
  }
  const Eigen::Index m = static_cast<Eigen::Index>(d.m);
  const Eigen::Index p = static_cast<Eigen::Index>(d.p);
  d.group_size = Eigen::VectorXd::Zero(m);
  d.group_x = Eigen::MatrixXd::Zero(m, p);
  d.group_y = Eigen::VectorXd::Zero(m);
  d.xtx = Eigen::MatrixXd::Zero(p, p);
  d.xty = Eigen::VectorXd::Zero(p);
  Eigen::MatrixXi cell_count = Eigen::MatrixXi::Zero(m, p);
  for (std::size_t j = 0; j < d.n; ++j) {
    Eigen::VectorXd x = Eigen::VectorXd::Zero(p);
    x(0) = 1.0;
    if (level[j] > 0) x(level[j]) = 1.0;
    d.group_size(group[j]) += 1.0;
    d.group_x.row(group[j]) += x.transpose();
    d.group_y(group[j]) += y[j];
    d.xtx.noalias() += x * x.transpose();
    d.xty += y[j] * x;
    ++cell_count(group[j], level[j]);
  }
  for (Eigen::Index i = 0; i < m; ++i) {
    if (d.group_size(i) == 0.0) {
      ThrowBadValue("mixed model group index", std::to_string(i) + " unused",
                    "every group index from 0 to " + std::to_string(d.m - 1) + " used");
    }
  }
  for (Eigen::Index k = 0; k < p; ++k) {
    if (cell_count.col(k).sum() == 0) {
      ThrowBadValue("mixed model level index", std::to_string(k) + " unused",
                    "every level index from 0 to " + std::to_string(d.p - 1) + " used");
    }
  }

  *balanced = (cell_count.array() == 1).all();
  return d;
}

// psi = theta^2 at the REML optimum: psi = 0 if the criterion rises from there, and every
// interior root of the score where it turns from negative to positive; the smallest criterion
// wins.
double RemlOptimum(const Design& d, const MixedModelOptions& options, int* evaluations) {
  std::vector<double> grid = {0.0};
  const int per_decade = options.grid_points_per_decade;
  for (int i = 0; i <= 20 * per_decade; ++i) {
    grid.push_back(std::pow(10.0, -10.0 + static_cast<double>(i) / per_decade));
  }
  std::vector<double> scores;
  for (double psi : grid) {
    const Evaluation ev = Evaluate(d, psi);
    if (!(ev.r2 > 0.0) || !std::isfinite(ev.criterion)) {
      ThrowBadValue("mixed model scores", "a residual sum of squares of " + FormatNumber(ev.r2),
                    "scores that the fixed effects do not fit exactly (constant within takes?)");
    }
    scores.push_back(ev.score);
    ++*evaluations;
  }
  std::vector<double> candidates;
  if (scores[0] >= 0.0) candidates.push_back(0.0);
  for (std::size_t i = 0; i + 1 < grid.size(); ++i) {
    if (scores[i] < 0.0 && scores[i + 1] >= 0.0) {
      candidates.push_back(BisectScore(d, grid[i], grid[i + 1], evaluations));
    }
  }
  if (candidates.empty()) {
    ThrowBadValue("mixed model scores",
                  "a REML criterion still falling at animator/residual variance ratio " +
                      FormatNumber(grid.back()),
                  "data with residual variation within animators");
  }
  double psi = candidates[0];
  double best = Evaluate(d, psi).criterion;
  for (std::size_t i = 1; i < candidates.size(); ++i) {
    const double value = Evaluate(d, candidates[i]).criterion;
    if (value < best) {
      best = value;
      psi = candidates[i];
    }
  }

  return psi;
}

// lmerTest's Satterthwaite machinery, with exact derivatives: the asymptotic covariance of the
// variance parameters (theta, sigma) and the Jacobian of vcov(beta) in them.
struct Satterthwaite {
  Eigen::Matrix2d varpar_covariance;
  Eigen::MatrixXd jac_theta;
  Eigen::MatrixXd jac_sigma;

  // One-dimensional Satterthwaite df of a contrast l: 2 (l'Vl)^2 / (g'A g), g the gradient of
  // l'Vl in (theta, sigma) (lmerTest's contest1D).
  double Df(const Eigen::RowVectorXd& l, double variance) const {
    const Eigen::Vector2d gradient(l * jac_theta * l.transpose(), l * jac_sigma * l.transpose());
    const double v = gradient.dot(varpar_covariance * gradient);
    return v > 0.0 ? 2.0 * variance * variance / v : std::numeric_limits<double>::infinity();
  }
};

// Deviance in (theta, sigma):
//   D = f(theta^2, sigma), f = log|V| + log|M| + r2(psi) / sigma^2 + (N - p) log(2 pi sigma^2),
// f_psi = tr(S) - |s|^2 / sigma^2, f_psipsi = -|S|_F^2 + 2 s'S s / sigma^2,
// f_psisigma = 2 |s|^2 / sigma^3, f_sigmasigma = 6 r2 / sigma^4 - 2 (N - p) / sigma^2.
// Warnings about the Hessian's eigenvalues go to r.summary.
Satterthwaite MakeSatterthwaite(const Design& d, const Evaluation& ev,
                                const MixedModelOptions& options, MixedModelResult& r) {
  const Eigen::Index m = static_cast<Eigen::Index>(d.m);
  const double psi = ev.psi;
  const double residual_df = static_cast<double>(d.n - d.p);
  const double sigma = r.sigma;
  const double sigma2 = r.residual_variance;
  const double s_norm2 = ev.s.squaredNorm();
  // S = D - W M^-1 W' is #groups by #groups; its trace, |S|_F^2 and s'S s are formed from p by p
  // products so that many animators cost O(m p^2), not O(m^2).
  const Eigen::MatrixXd wtw = ev.w.transpose() * ev.w;
  const Eigen::MatrixXd c_wtw = ev.m_inverse * wtw;
  const Eigen::VectorXd wts = ev.w.transpose() * ev.s;
  double d_quadratic = 0.0;  // sum_i D_i w_i' M^-1 w_i
  for (Eigen::Index i = 0; i < m; ++i) {
    d_quadratic += ev.d_diag(i) * ev.w.row(i).dot(ev.m_inverse * ev.w.row(i).transpose());
  }
  const double trace_s = ev.d_diag.sum() - c_wtw.trace();
  const double s_frobenius2 = ev.d_diag.squaredNorm() - 2.0 * d_quadratic + (c_wtw * c_wtw).trace();
  const double s_quadratic = ev.s.dot(ev.d_diag.cwiseProduct(ev.s)) - wts.dot(ev.m_inverse * wts);
  const double f_psi = trace_s - s_norm2 / sigma2;
  const double f_psipsi = -s_frobenius2 + 2.0 * s_quadratic / sigma2;
  const double f_psisigma = 2.0 * s_norm2 / (sigma2 * sigma);
  const double f_sigmasigma = 6.0 * ev.r2 / (sigma2 * sigma2) - 2.0 * residual_df / sigma2;
  Eigen::Matrix2d hessian;
  hessian(0, 0) = 2.0 * f_psi + 4.0 * psi * f_psipsi;
  hessian(0, 1) = hessian(1, 0) = 2.0 * r.theta * f_psisigma;
  hessian(1, 1) = f_sigmasigma;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> hessian_eigen(hessian);
  Eigen::Matrix2d hessian_pinv = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 2; ++i) {
    const double value = hessian_eigen.eigenvalues()(i);
    if (value < -options.hessian_tolerance) {
      r.summary.warnings.push_back("the deviance Hessian has a negative eigenvalue " +
                                   FormatNumber(value) + " (lmerTest: model failed to converge)");
    } else if (value <= options.hessian_tolerance) {
      r.summary.warnings.push_back("the deviance Hessian has an eigenvalue close to zero, " +
                                   FormatNumber(value) +
                                   " (lmerTest: model may not have converged)");
    }
    if (value > options.hessian_tolerance) {
      const Eigen::Vector2d v = hessian_eigen.eigenvectors().col(i);
      hessian_pinv += v * v.transpose() / value;
    }
  }
  Satterthwaite out;
  out.varpar_covariance = 2.0 * hessian_pinv;
  // Jacobian of vcov(beta) = sigma^2 M^-1(theta^2): d/dtheta = sigma^2 2 theta M^-1 W'W M^-1,
  // d/dsigma = 2 sigma M^-1.
  out.jac_theta = sigma2 * 2.0 * r.theta * ev.m_inverse * wtw * ev.m_inverse;
  out.jac_sigma = 2.0 * sigma * ev.m_inverse;
  return out;
}

// The fixed effects with Satterthwaite df, t, p and confidence intervals (lmerTest's summary).
void SetFixedEffects(const Satterthwaite& satterthwaite, const MixedModelOptions& options,
                     MixedModelResult& r) {
  const Eigen::Index p = r.beta.size();
  for (Eigen::Index j = 0; j < p; ++j) {
    FixedEffect e;
    e.name = j == 0 ? "(Intercept)" : "take" + std::to_string(j + 1);
    const Eigen::RowVectorXd l = Eigen::RowVectorXd::Unit(p, j);
    const double variance = r.beta_covariance(j, j);
    e.estimate = r.beta(j);
    e.standard_error = std::sqrt(variance);
    e.df = satterthwaite.Df(l, variance);
    e.t = e.estimate / e.standard_error;
    double half = 0.0;
    if (std::isfinite(e.df)) {
      const bm::students_t_distribution<double> dist(e.df);
      e.p_value = 2.0 * bm::cdf(bm::complement(dist, std::abs(e.t)));
      half = bm::quantile(dist, 1.0 - (1.0 - options.conf_level) / 2.0) * e.standard_error;
    } else {
      const bm::normal_distribution<double> normal;
      e.p_value = 2.0 * bm::cdf(bm::complement(normal, std::abs(e.t)));
      half = bm::quantile(normal, 1.0 - (1.0 - options.conf_level) / 2.0) * e.standard_error;
    }
    e.conf_int = {e.estimate - half, e.estimate + half, options.conf_level};
    r.fixed_effects.push_back(e);
  }
}

// The F test of the take effect: lmerTest uses type I contrasts for a model with one term (its
// type III reduces to them), the rows of t(doolittle(X'X)$L) of the take columns.
void SetTakeTest(const Design& d, const Satterthwaite& satterthwaite, MixedModelResult& r) {
  const Eigen::Index p = static_cast<Eigen::Index>(d.p);
  const double sigma2 = r.residual_variance;
  r.contrast = DoolittleL(d.xtx).transpose().bottomRows(p - 1);
  const Eigen::MatrixXd vl = r.contrast * r.beta_covariance * r.contrast.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> vl_eigen(vl);
  // Descending order, as R's eigen().
  std::vector<Eigen::Index> order(static_cast<std::size_t>(vl.rows()));
  for (Eigen::Index i = 0; i < vl.rows(); ++i) order[i] = vl.rows() - 1 - i;
  const double largest = vl_eigen.eigenvalues()(order[0]);
  const double tolerance =
      std::max(std::sqrt(std::numeric_limits<double>::epsilon()) * largest, 0.0);
  double t2_sum = 0.0;
  for (Eigen::Index idx : order) {
    const double value = vl_eigen.eigenvalues()(idx);
    if (!(value > tolerance)) continue;
    const Eigen::RowVectorXd direction = vl_eigen.eigenvectors().col(idx).transpose() * r.contrast;
    const double estimate = direction.dot(r.beta);
    t2_sum += estimate * estimate / value;
    r.direction_df.push_back(satterthwaite.Df(direction, value));
  }
  const double q = static_cast<double>(r.direction_df.size());
  const double f = t2_sum / q;
  r.take_test = MakeFTest(f, q, CombineDf(r.direction_df), f * sigma2 * q);
}

// The repeated-measures ANOVA of a balanced design, which the mixed model's F test must equal
// when the animator variance is interior; warnings when it is undefined or differs.
void CompareWithRmAnova(const Design& d, MixedModelResult& r) {
  const Eigen::Index p = static_cast<Eigen::Index>(d.p);
  const std::span<const int> group = d.group;
  const std::span<const int> level = d.level;
  const std::span<const double> y = d.y;
  if (r.summary.balanced) {
    // Two-way layout without replication: SS_take = n sum_j (mean_j - mean)^2, SS_error = sum
    // (y_ij - mean_i - mean_j + mean)^2, F = (SS_take / (k - 1)) / (SS_error / ((n - 1)(k - 1))).
    Eigen::VectorXd group_mean = d.group_y / static_cast<double>(d.p);
    Eigen::VectorXd level_mean = Eigen::VectorXd::Zero(p);
    double grand = 0.0;
    for (std::size_t j = 0; j < d.n; ++j) {
      level_mean(level[j]) += y[j];
      grand += y[j];
    }
    level_mean /= static_cast<double>(d.m);
    grand /= static_cast<double>(d.n);
    double ss_take = 0.0;
    for (Eigen::Index k = 0; k < p; ++k) {
      ss_take += static_cast<double>(d.m) * (level_mean(k) - grand) * (level_mean(k) - grand);
    }
    double ss_error = 0.0;
    for (std::size_t j = 0; j < d.n; ++j) {
      const double v = y[j] - group_mean(group[j]) - level_mean(level[j]) + grand;
      ss_error += v * v;
    }
    const double df1 = static_cast<double>(d.p - 1);
    const double df2 = static_cast<double>((d.m - 1) * (d.p - 1));
    if (ss_error > 0.0) {
      r.rm_anova = MakeFTest((ss_take / df1) / (ss_error / df2), df1, df2, ss_take);
      const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-8 * std::abs(b); };
      r.agrees_with_rm_anova =
          close(r.take_test.f, r.rm_anova->f) && close(r.take_test.den_df, r.rm_anova->den_df);
    } else {
      r.summary.warnings.push_back(
          "the repeated-measures ANOVA is undefined: no animator-by-take residual variation");
    }
  } else {
    r.summary.warnings.push_back(
        "unbalanced design (not every animator has every take exactly once): no "
        "repeated-measures ANOVA to compare with");
  }
  if (r.boundary) {
    r.summary.warnings.push_back(
        "the animator variance estimate is at its boundary (0; lme4: boundary (singular) fit): "
        "the mixed model reduces to ordinary least squares, " +
        Describe(r.take_test) +
        (r.rm_anova ? ", which differs from the repeated-measures ANOVA " + Describe(*r.rm_anova)
                    : std::string()));
  } else if (r.rm_anova && !r.agrees_with_rm_anova) {
    r.summary.warnings.push_back("the mixed-model " + Describe(r.take_test) +
                                 " differs from the repeated-measures ANOVA " +
                                 Describe(*r.rm_anova));
  }
}

}  // namespace

MixedModelResult FitRandomInterceptModel(std::span<const int> group, std::span<const int> level,
                                         std::span<const double> y,
                                         const MixedModelOptions& options) {
  options.Validate("mixed model options");
  MixedModelResult r;
  const Design d = MakeDesign(group, level, y, &r.summary.balanced);
  r.summary.observations = d.n;
  r.summary.groups = d.m;
  r.summary.levels = d.p;
  const double psi = RemlOptimum(d, options, &r.summary.score_evaluations);

  const Eigen::Index m = static_cast<Eigen::Index>(d.m);
  const Evaluation ev = Evaluate(d, psi);
  const double residual_df = static_cast<double>(d.n - d.p);
  r.boundary = psi == 0.0;
  r.theta = std::sqrt(psi);
  r.residual_variance = ev.r2 / residual_df;
  r.sigma = std::sqrt(r.residual_variance);
  r.group_variance = psi * r.residual_variance;
  r.icc = r.group_variance / (r.group_variance + r.residual_variance);
  r.reml_criterion = ev.criterion;
  r.beta = ev.beta;
  r.beta_covariance = r.residual_variance * ev.m_inverse;

  // Random intercepts (conditional modes) and conditional residuals.
  r.random_effects.resize(d.m);
  for (Eigen::Index i = 0; i < m; ++i) {
    r.random_effects[i] = psi / (1.0 + d.group_size(i) * psi) * ev.group_residual(i);
  }
  r.fitted.resize(d.n);
  r.residuals.resize(d.n);
  for (std::size_t j = 0; j < d.n; ++j) {
    r.residuals[j] = ev.residual(j) - r.random_effects[group[j]];
    r.fitted[j] = y[j] - r.residuals[j];
  }

  const Satterthwaite satterthwaite = MakeSatterthwaite(d, ev, options, r);
  SetFixedEffects(satterthwaite, options, r);
  SetTakeTest(d, satterthwaite, r);
  CompareWithRmAnova(d, r);
  return r;
}

}  // namespace mmh::stats
