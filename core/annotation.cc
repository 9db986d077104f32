#include "core/annotation.h"

#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/error_text.h"
#include "core/text_parsing.h"

namespace mmh {
namespace {

void CheckValue(double value, const std::string& where) {
  if (!std::isfinite(value) || value < kMinAnnotation || value > kMaxAnnotation) {
    ThrowBadValue(where + ", value", FormatNumber(value), "a number in [-5, 5]");
  }
}

}  // namespace

Annotation ReadAnnotationCsv(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  Annotation annotation;
  std::istringstream lines(text);
  std::string line;
  std::size_t line_number = 0;
  bool header_seen = false;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string_view content = Trim(line);
    if (content.empty()) continue;
    const std::string where = path.string() + ":" + std::to_string(line_number);
    if (!header_seen) {
      const auto names = SplitCsvFields(content);
      if (names.size() != 2 || Trim(names[0]) != "timestamp" || Trim(names[1]) != "value") {
        ThrowBadValue(where, "the header " + Quote(content), "the header 'timestamp,value'");
      }
      header_seen = true;
      continue;
    }
    const auto fields = SplitCsvFields(content);
    if (fields.size() != 2) {
      ThrowBadValue(where, std::to_string(fields.size()) + " fields (" + Quote(content) + ")",
                    "2 fields: timestamp,value");
    }
    double timestamp = 0.0, value = 0.0;
    if (!ParseDouble(fields[0], &timestamp) || !std::isfinite(timestamp)) {
      ThrowBadValue(where + ", timestamp", Quote(fields[0]), "a finite number");
    }
    if (!ParseDouble(fields[1], &value)) {
      ThrowBadValue(where + ", value", Quote(fields[1]), "a number in [-5, 5]");
    }
    CheckValue(value, where);
    if (!annotation.timestamps.empty() && !(timestamp > annotation.timestamps.back())) {
      ThrowBadValue(
          where + ", timestamp", FormatNumber(timestamp),
          "greater than the previous timestamp " + FormatNumber(annotation.timestamps.back()));
    }
    annotation.timestamps.push_back(timestamp);
    annotation.values.push_back(value);
  }
  if (annotation.values.empty()) {
    ThrowBadValue(path.string(), header_seen ? "a header but no rows" : "an empty file",
                  "the header 'timestamp,value' and one row per frame");
  }
  return annotation;
}

void ValidateAnnotation(const Annotation& annotation, const std::string& name) {
  if (annotation.timestamps.size() != annotation.values.size()) {
    ThrowBadValue(name,
                  std::to_string(annotation.timestamps.size()) + " timestamps for " +
                      std::to_string(annotation.values.size()) + " values",
                  "one timestamp per value");
  }
  for (std::size_t i = 0; i < annotation.size(); ++i) {
    // Built only on error: this loop runs over every frame.
    auto where = [&] { return name + ", frame " + std::to_string(i); };
    const double value = annotation.values[i];
    if (!std::isfinite(value) || value < kMinAnnotation || value > kMaxAnnotation) {
      CheckValue(value, where());
    }
    if (!std::isfinite(annotation.timestamps[i]) ||
        (i > 0 && !(annotation.timestamps[i] > annotation.timestamps[i - 1]))) {
      ThrowBadValue(where() + ", timestamp", FormatNumber(annotation.timestamps[i]),
                    "finite and greater than the previous timestamp");
    }
  }
}

void WriteAnnotationCsv(const std::filesystem::path& path, const Annotation& annotation) {
  ValidateAnnotation(annotation, path.string());
  if (annotation.values.empty()) {
    ThrowBadValue(path.string(), "an empty annotation",
                  "at least one row (the reader rejects none)");
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "timestamp,value\n";
    for (std::size_t i = 0; i < annotation.size(); ++i) {
      out << FormatNumber(annotation.timestamps[i]) << ',' << FormatNumber(annotation.values[i])
          << '\n';
    }
  });
}

}  // namespace mmh
