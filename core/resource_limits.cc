#include "core/resource_limits.h"

#include "core/error.h"
#include "core/error_text.h"

namespace mmh {

int ParseThreadCount(std::string_view text, const std::string& flag) {
  // 0 is refused too: without --threads a run uses every core, so an explicit 0 is a mistake
  // (an unset variable in a script, say).
  const std::string expected = "an integer from 1 to " + std::to_string(kMaxThreads) +
                               " worker threads (without --threads: all cores)";
  bool digits = !text.empty() && text.size() <= 9;
  for (char c : text) digits = digits && c >= '0' && c <= '9';
  if (!digits) ThrowBadValue(flag, Quote(text, 24), expected);
  const long value = std::stol(std::string(text));
  if (value < 1 || value > kMaxThreads) ThrowBadValue(flag, std::to_string(value), expected);
  return static_cast<int>(value);
}

void RequireAtMost(std::int64_t count, std::int64_t limit, const std::string& where,
                   const std::string& what) {
  if (count > limit) {
    ThrowBadValue(where, std::to_string(count) + " " + what,
                  "at most " + std::to_string(limit) + " " + what +
                      " (a resource limit: more would need absurd memory or time)");
  }
}

}  // namespace mmh
