// Sample mean and variance computed the way R computes them (mean(): long-double sum plus one
// correction pass; var(): two passes about that mean), so that statistics built on them agree
// with R to the last few bits, and average ranks (R's rank(), ties.method = "average").
#pragma once

#include <span>
#include <vector>

namespace mmh::stats {

// Arithmetic mean; NaN for an empty sample.
double Mean(std::span<const double> x);

// Unbiased sample variance (denominator n - 1); NaN for fewer than two values.
double Variance(std::span<const double> x);

// Ranks 1..n with ties given the average of the ranks they span (R: rank(x)); ties are exact
// equality, as in R.
std::vector<double> AverageRanks(std::span<const double> x);

}  // namespace mmh::stats
