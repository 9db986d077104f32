// Errors of the harness. An InputError is bad input or usage (exit code 2); anything else that
// escapes to the command line is a failure of the work (exit code 1).
#pragma once

#include <stdexcept>
#include <string>

namespace mmh {

// Bad input: a file, field or value the user can fix. The message names where (file and line, or
// the config key), the offending value and what was expected.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// "where: got VALUE, expected EXPECTATION" — the one shape every input error message takes.
std::string DescribeBadValue(const std::string& where, const std::string& value,
                             const std::string& expected);

// Throws InputError(DescribeBadValue(...)).
[[noreturn]] void ThrowBadValue(const std::string& where, const std::string& value,
                                const std::string& expected);

// Range checks for Options::Validate: each throws InputError(DescribeBadValue(where, value, ...))
// naming the expectation (and the unit, when given).
void RequireFinite(double value, const std::string& where);
void RequirePositive(double value, const std::string& where, const std::string& unit = "");
void RequireNonNegative(double value, const std::string& where, const std::string& unit = "");
void RequireProbability(double value, const std::string& where);

// Formats a double for messages: shortest form that reads back to the same value.
std::string FormatNumber(double value);

}  // namespace mmh
