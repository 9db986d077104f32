// A duration for people to read: progress bars' time left, a sweep's ETA.
#pragma once

#include <string>

namespace mmh {

// "42 s" below 90 s, "12 min" below 90 min, "1.5 h" above.
std::string FormatDuration(double seconds);

}  // namespace mmh
