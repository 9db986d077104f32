// Like/dislike annotation of a take: one slider value per frame, in [-5, 5] (the paper's scale:
// -5 dislike, +5 like). On disk: CSV with the header "timestamp,value".
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mmh {

struct Annotation {
  // Seconds, strictly increasing; #frames entries.
  std::vector<double> timestamps;
  // Slider values in [kMinAnnotation, kMaxAnnotation]; #frames entries.
  std::vector<double> values;

  std::size_t size() const { return values.size(); }
};

inline constexpr double kMinAnnotation = -5.0;
inline constexpr double kMaxAnnotation = 5.0;

// Reads and validates: header "timestamp,value", two finite numbers a row, values in [-5, 5],
// increasing timestamps, at least one row. Errors name the file, line, value and expectation.
Annotation ReadAnnotationCsv(const std::filesystem::path& path);

// Writes atomically, numbers in shortest round-trip form.
void WriteAnnotationCsv(const std::filesystem::path& path, const Annotation& annotation);

// Checks sizes, finiteness, range and increasing timestamps; `name` starts the message.
void ValidateAnnotation(const Annotation& annotation, const std::string& name);

}  // namespace mmh
