// The R oracle of the statistics tests: tests/data/study/golden.json, written by
// tests/data/study/make_golden.R (R's own t.test, friedman.test, chisq.test, binom.test,
// shapiro.test, aov, lme4::lmer and lmerTest::anova on the data stored beside each result).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/options.h"
#include "stats/htest.h"

namespace mmh::stats::golden {

// The matching tolerance of the issue: 1e-10 relative.
inline constexpr double kRelative = 1e-10;

inline nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

inline const nlohmann::json& Golden() {
  static const nlohmann::json golden =
      ReadJsonFile(std::filesystem::path(MMH_TEST_DATA_DIR) / "study" / "golden.json");
  return golden;
}

// A JSON number, or +-infinity for null (R's -Inf / Inf ends of one-sided intervals are written as
// null); `sign` says which infinity.
inline double Number(const nlohmann::json& value, double sign = 1.0) {
  return value.is_null() ? sign * std::numeric_limits<double>::infinity() : value.get<double>();
}

inline std::vector<double> Vector(const nlohmann::json& value) {
  return value.get<std::vector<double>>();
}

inline Eigen::MatrixXd Matrix(const nlohmann::json& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()),
                    static_cast<Eigen::Index>(rows.at(0).size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) m(i, j) = rows[i][j].get<double>();
  }
  return m;
}

// |actual - expected| <= tolerance |expected| (infinities must be equal; exact zeros are compared
// with an absolute tolerance of `tolerance`, since no relative one exists).
inline ::testing::AssertionResult Near(double actual, double expected,
                                       double tolerance = kRelative) {
  if (std::isinf(expected) || std::isinf(actual)) {
    if (actual == expected) return ::testing::AssertionSuccess();
  } else {
    const double scale = expected == 0.0 ? 1.0 : std::abs(expected);
    if (std::abs(actual - expected) <= tolerance * scale) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "got " << actual << ", R " << expected << " (relative difference "
         << std::abs(actual - expected) / std::abs(expected) << ", tolerance " << tolerance << ")";
}

// R's name of an alternative ("two.sided", "less", "greater").
inline Alternative AlternativeNamed(const std::string& name) {
  for (const auto& [value, text] : EnumNames(Alternative{})) {
    if (name == text) return value;
  }
  ADD_FAILURE() << "unknown alternative " << name;
  return Alternative::kTwoSided;
}

#define MMH_EXPECT_NEAR_R(actual, expected, ...) \
  EXPECT_TRUE(::mmh::stats::golden::Near((actual), (expected)__VA_OPT__(, ) __VA_ARGS__)) << #actual

}  // namespace mmh::stats::golden
