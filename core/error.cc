#include "core/error.h"

#include <charconv>
#include <cmath>

namespace mmh {

std::string DescribeBadValue(const std::string& where, const std::string& value,
                             const std::string& expected) {
  return where + ": got " + value + ", expected " + expected;
}

void ThrowBadValue(const std::string& where, const std::string& value,
                   const std::string& expected) {
  throw InputError(DescribeBadValue(where, value, expected));
}

std::string FormatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, end);
}

}  // namespace mmh
