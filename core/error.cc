#include "core/error.h"

#include <charconv>
#include <cmath>

#include "core/error_text.h"

namespace mmh {

std::string DescribeBadValue(const std::string& where, const std::string& value,
                             const std::string& expected) {
  // The value is the part that may come from outside: a safety net for readers that did not
  // Quote() it (callers quote fields themselves, with a tighter limit).
  return where + ": got " + EscapeForMessage(value, 160) + ", expected " + expected;
}

void ThrowBadValue(const std::string& where, const std::string& value,
                   const std::string& expected) {
  throw InputError(DescribeBadValue(where, value, expected));
}

namespace {
std::string WithUnit(const std::string& expected, const std::string& unit) {
  return unit.empty() ? expected : expected + " " + unit;
}
}  // namespace

void RequireFinite(double value, const std::string& where) {
  if (!std::isfinite(value)) ThrowBadValue(where, FormatNumber(value), "a finite number");
}

void RequirePositive(double value, const std::string& where, const std::string& unit) {
  if (!std::isfinite(value) || value <= 0) {
    ThrowBadValue(where, FormatNumber(value), WithUnit("a finite number > 0", unit));
  }
}

void RequireNonNegative(double value, const std::string& where, const std::string& unit) {
  if (!std::isfinite(value) || value < 0) {
    ThrowBadValue(where, FormatNumber(value), WithUnit("a finite number >= 0", unit));
  }
}

void RequireProbability(double value, const std::string& where) {
  if (!std::isfinite(value) || value < 0 || value > 1) {
    ThrowBadValue(where, FormatNumber(value), "a probability in [0, 1]");
  }
}

std::string FormatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, end);
}

}  // namespace mmh
