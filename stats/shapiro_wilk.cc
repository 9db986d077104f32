#include "stats/shapiro_wilk.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "stats/htest.h"

namespace mmh::stats {
namespace {

namespace bm = boost::math;

// c[0] + c[1] x + ... + c[d] x^d.
template <std::size_t N>
double Polynomial(const double (&c)[N], double x) {
  double value = 0.0;
  for (std::size_t i = N; i-- > 0;) value = value * x + c[i];
  return value;
}

// The coefficients a_1..a_m (m = n / 2) of the upper half of the antisymmetric weight vector: the
// largest observation gets +a_1, the smallest -a_1 (AS R94: Royston 1992's polynomial
// approximations for the two most extreme weights, normal scores m_i = Phi^-1((i - 3/8) / (n +
// 1/4)) rescaled for the rest).
std::vector<double> Weights(std::size_t n) {
  const std::size_t half = n / 2;
  std::vector<double> a(half);
  if (n == 3) {
    a[0] = std::sqrt(0.5);  // exact; W is scale-free in a
    return a;
  }
  // Royston (1992), Table 1: the weights of the largest and second largest observation as
  // polynomials in u = 1 / sqrt(n).
  static constexpr double kC1[] = {0.0, 0.221157, -0.147981, -2.07119, 4.434685, -2.706056};
  static constexpr double kC2[] = {0.0, 0.042981, -0.293762, -1.752461, 5.682633, -3.582633};
  const double dn = static_cast<double>(n);
  const bm::normal_distribution<double> normal;
  std::vector<double> m(half);
  double sum_m2 = 0.0;
  for (std::size_t i = 0; i < half; ++i) {
    // m[i] is the normal score of the (i + 1)-th smallest value (negative).
    m[i] = bm::quantile(normal, (static_cast<double>(i + 1) - 0.375) / (dn + 0.25));
    sum_m2 += m[i] * m[i];
  }
  sum_m2 *= 2.0;
  const double norm_m = std::sqrt(sum_m2);
  const double u = 1.0 / std::sqrt(dn);
  const double a1 = Polynomial(kC1, u) - m[0] / norm_m;
  std::size_t first_scaled = 1;
  double scale = 0.0;
  if (n > 5) {
    const double a2 = Polynomial(kC2, u) - m[1] / norm_m;
    scale = std::sqrt((sum_m2 - 2.0 * m[0] * m[0] - 2.0 * m[1] * m[1]) /
                      (1.0 - 2.0 * a1 * a1 - 2.0 * a2 * a2));
    a[1] = a2;
    first_scaled = 2;
  } else {
    scale = std::sqrt((sum_m2 - 2.0 * m[0] * m[0]) / (1.0 - 2.0 * a1 * a1));
  }
  a[0] = a1;
  for (std::size_t i = first_scaled; i < half; ++i) a[i] = -m[i] / scale;
  return a;
}

}  // namespace

nlohmann::json ShapiroWilkResult::ToJson() const {
  return {{"test", "Shapiro-Wilk normality test"}, {"n", n}, {"w", w}, {"p_value", p_value}};
}

ShapiroWilkResult ShapiroWilkTest(std::span<const double> sample) {
  RequireAllFinite(sample, "Shapiro-Wilk sample");
  const std::size_t n = sample.size();
  if (n < 3 || n > 5000) {
    ThrowBadValue("Shapiro-Wilk sample", std::to_string(n) + " values",
                  "between 3 and 5000 values (AS R94)");
  }
  std::vector<double> x(sample.begin(), sample.end());
  std::sort(x.begin(), x.end());
  double range = x.back() - x.front();
  if (range == 0.0) {
    ThrowBadValue("Shapiro-Wilk sample", "all values equal to " + FormatNumber(x.front()),
                  "values that are not all identical (R: all 'x' values are identical)");
  }
  // R rescales tiny ranges so that the algorithm's zero-range guard (1e-19) cannot trigger.
  if (range < 1e-10) {
    for (double& v : x) v /= range;
    range = x.back() - x.front();
  }

  // W as the squared correlation between the ordered sample and the weights (AS R94), with 1 - W
  // formed as (s - c)(s + c) / s^2 to keep its relative accuracy when W is near 1.
  const std::vector<double> half = Weights(n);
  std::vector<double> a(n, 0.0);
  for (std::size_t i = 0; i < half.size(); ++i) {
    a[i] = -half[i];
    a[n - 1 - i] = half[i];
  }
  double mean_a = 0.0;
  double mean_x = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean_a += a[i];
    mean_x += x[i] / range;
  }
  mean_a /= static_cast<double>(n);
  mean_x /= static_cast<double>(n);
  double ssa = 0.0;
  double ssx = 0.0;
  double sax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double da = a[i] - mean_a;
    const double dx = x[i] / range - mean_x;
    ssa += da * da;
    ssx += dx * dx;
    sax += da * dx;
  }
  const double root = std::sqrt(ssa * ssx);
  const double one_minus_w = (root - sax) * (root + sax) / (ssa * ssx);

  ShapiroWilkResult r;
  r.n = n;
  r.w = 1.0 - one_minus_w;
  if (n == 3) {
    // Exact distribution for n = 3 (Shapiro & Wilk 1965): P = (6 / pi) (asin(sqrt(W)) -
    // asin(sqrt(3 / 4))), with AS R94's published constants.
    const double six_over_pi = 1.90985931710274;
    const double asin_sqrt_three_quarters = 1.04719755119660;
    r.p_value = std::max(0.0, six_over_pi * (std::asin(std::sqrt(r.w)) - asin_sqrt_three_quarters));
    return r;
  }
  const double dn = static_cast<double>(n);
  double y = std::log(one_minus_w);
  double mean = 0.0;
  double sd = 0.0;
  if (n <= 11) {
    // Royston (1992): for small n, -log(gamma - log(1 - W)) is close to normal.
    static constexpr double kGamma[] = {-2.273, 0.459};
    static constexpr double kC3[] = {0.544, -0.39978, 0.025054, -6.714e-4};
    static constexpr double kC4[] = {1.3822, -0.77857, 0.062767, -0.0020322};
    const double gamma = Polynomial(kGamma, dn);
    if (y >= gamma) {
      r.p_value = 1e-99;  // beyond the approximation's support; R's value
      return r;
    }
    y = -std::log(gamma - y);
    mean = Polynomial(kC3, dn);
    sd = std::exp(Polynomial(kC4, dn));
  } else {
    static constexpr double kC5[] = {-1.5861, -0.31082, -0.083751, 0.0038915};
    static constexpr double kC6[] = {-0.4803, -0.082676, 0.0030302};
    const double log_n = std::log(dn);
    mean = Polynomial(kC5, log_n);
    sd = std::exp(Polynomial(kC6, log_n));
  }
  r.p_value = bm::cdf(bm::complement(bm::normal_distribution<double>(mean, sd), y));
  return r;
}

}  // namespace mmh::stats
