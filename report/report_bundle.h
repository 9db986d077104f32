// The report's browser code, bundled by esbuild at build time (report/CMakeLists.txt) and compiled
// in: null-terminated arrays of string chunks whose concatenation is the script or the style.
#pragma once

#include <string>

namespace mmh::report::internal {

extern const char* const kReportScriptChunks[];
extern const char* const kReportStyleChunks[];

// The concatenation of a chunk array.
inline std::string JoinChunks(const char* const* chunks) {
  std::string text;
  for (; *chunks != nullptr; ++chunks) text += *chunks;
  return text;
}

}  // namespace mmh::report::internal
