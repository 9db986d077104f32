#include "stats/htest.h"

#include <array>
#include <cmath>

#include "core/error.h"

namespace mmh::stats {

std::span<const std::pair<Alternative, const char*>> EnumNames(Alternative) {
  static constexpr std::array<std::pair<Alternative, const char*>, 3> kNames{{
      {Alternative::kTwoSided, "two.sided"},
      {Alternative::kLess, "less"},
      {Alternative::kGreater, "greater"},
  }};
  return kNames;
}

nlohmann::json FiniteOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json ConfidenceInterval::ToJson() const {
  return {{"lower", FiniteOrNull(lower)}, {"upper", FiniteOrNull(upper)}, {"level", level}};
}

void RequireAllFinite(std::span<const double> values, const std::string& where) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      ThrowBadValue(where + "[" + std::to_string(i) + "]", FormatNumber(values[i]),
                    "a finite number");
    }
  }
}

void RequireConfidenceLevel(double level, const std::string& where) {
  if (!(level > 0.0 && level < 1.0)) {
    ThrowBadValue(where, FormatNumber(level), "a confidence level in (0, 1)");
  }
}

}  // namespace mmh::stats
