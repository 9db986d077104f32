// The vocabulary shared by the hypothesis tests of study/ (the shape of R's "htest" objects): the
// alternative hypothesis, confidence intervals, sample checks, and JSON numbers that may be
// infinite (one-sided intervals).
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>

namespace mmh::stats {

// Direction of the alternative hypothesis, named as in R (`alternative = "two.sided"`, ...).
enum class Alternative { kTwoSided, kLess, kGreater };
std::span<const std::pair<Alternative, const char*>> EnumNames(Alternative);

// A confidence interval; a one-sided interval has an infinite end (R: -Inf or Inf).
struct ConfidenceInterval {
  double lower = 0.0;
  double upper = 0.0;
  double level = 0.95;  // coverage probability (R's conf.level)

  // {"lower", "upper", "level"}; an infinite end is written as null.
  nlohmann::json ToJson() const;
};

// `value` as a JSON number, or null when it is not finite (JSON has no infinity or NaN).
nlohmann::json FiniteOrNull(double value);

// Throws InputError naming `where` and the index unless every value is finite (R drops NA; this
// library refuses them so that a bad value is never silently ignored).
void RequireAllFinite(std::span<const double> values, const std::string& where);

// Throws InputError unless 0 < level < 1 (R: "'conf.level' must be a single number between 0
// and 1").
void RequireConfidenceLevel(double level, const std::string& where);

}  // namespace mmh::stats
