#include "core/text_parsing.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace mmh {

std::string ReadTextFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    ThrowBadValue(path.string(), "a path that does not exist", "an existing, readable file");
  }
  if (std::filesystem::is_directory(path, ec)) {
    ThrowBadValue(path.string(), "a folder", "a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ThrowBadValue(path.string(), "an unreadable file (" + std::string(std::strerror(errno)) + ")",
                  "a readable file");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::vector<std::string_view> SplitFields(std::string_view line, std::string_view delimiters) {
  std::vector<std::string_view> fields;
  std::size_t pos = 0;
  while (pos < line.size()) {
    const std::size_t start = line.find_first_not_of(delimiters, pos);
    if (start == std::string_view::npos) break;
    std::size_t end = line.find_first_of(delimiters, start);
    if (end == std::string_view::npos) end = line.size();
    fields.push_back(line.substr(start, end - start));
    pos = end;
  }
  return fields;
}

std::vector<std::string_view> SplitCsvFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
        Trim(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool ParseDouble(std::string_view text, double* value) {
  text = Trim(text);
  if (text.empty()) return false;
  if (text.front() == '+') {
    text.remove_prefix(1);
    if (text.empty() || text.front() == '-' || text.front() == '+') return false;
  }
  const char* end = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(text.data(), end, *value);
  return ec == std::errc() && ptr == end;
}

std::string_view Trim(std::string_view text) {
  const char* kSpace = " \t\r\n";
  const std::size_t start = text.find_first_not_of(kSpace);
  if (start == std::string_view::npos) return {};
  const std::size_t end = text.find_last_not_of(kSpace);
  return text.substr(start, end - start + 1);
}

void ForEachDataRow(
    const std::filesystem::path& path, std::size_t field_count, const std::string& layout,
    const std::function<void(const std::string& where, const std::vector<std::string_view>& fields,
                             int line)>& row) {
  const std::string text = ReadTextFile(path);
  std::istringstream lines(text);
  std::string line;
  int line_number = 0;
  while (std::getline(lines, line)) {
    ++line_number;
    const std::string_view content = Trim(line);
    if (content.empty() || content.front() == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(line_number);
    const auto fields = SplitFields(content, " \t");
    if (fields.size() != field_count) {
      ThrowBadValue(where,
                    std::to_string(fields.size()) + " fields ('" + std::string(content) + "')",
                    layout);
    }
    row(where, fields, line_number);
  }
}

}  // namespace mmh
