#include "core/text_parsing.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/error_text.h"

namespace mmh {

namespace {

std::string FormatBytes(std::size_t bytes) {
  if (bytes >= (std::size_t{1} << 20) && bytes % (std::size_t{1} << 20) == 0) {
    return std::to_string(bytes >> 20) + " MiB";
  }
  return std::to_string(bytes) + " bytes";
}

// Names what the start of a file that is not UTF-8 text looks like, or "" if it may be text.
std::string NotText(std::string_view head) {
  auto starts = [&](std::string_view prefix) { return head.starts_with(prefix); };
  using namespace std::string_view_literals;
  if (starts("\xFF\xFE\0\0"sv) || starts("\0\0\xFE\xFF"sv)) {
    return "a UTF-32 file (byte-order mark)";
  }
  if (starts("\xFF\xFE") || starts("\xFE\xFF")) return "a UTF-16 file (byte-order mark)";
  const std::size_t nul = head.find('\0');
  if (nul == std::string_view::npos) return "";
  // UTF-16 without a mark: ASCII characters with a NUL byte beside every one.
  if (head.size() >= 4 && (head[1] == '\0' || head[0] == '\0') &&
      (head[3] == '\0' || head[2] == '\0') && head.find("\0\0"sv) == std::string_view::npos) {
    return "a UTF-16 file (NUL bytes between the characters)";
  }
  return "binary data (a NUL byte at offset " + std::to_string(nul) + ")";
}

// Reads a whole file in chunks up to `max_bytes` (a device or FIFO has no size to check first);
// with `text_only`, the first chunk must not look like UTF-16/32 or binary data.
std::string ReadBounded(const std::filesystem::path& path, std::size_t max_bytes,
                        const std::string& expected, bool text_only) {
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
  std::string bytes;
  constexpr std::size_t kChunk = 1 << 16;
  while (in) {
    const std::size_t old_size = bytes.size();
    bytes.resize(old_size + kChunk);
    in.read(bytes.data() + old_size, kChunk);
    bytes.resize(old_size + static_cast<std::size_t>(in.gcount()));
    if (text_only && old_size == 0) {
      const std::string what = NotText(bytes);
      if (!what.empty()) ThrowBadValue(path.string(), what, expected);
    }
    if (bytes.size() > max_bytes) {
      ThrowBadValue(path.string(), "more than " + FormatBytes(max_bytes),
                    expected + " of at most " + FormatBytes(max_bytes));
    }
  }
  if (in.bad()) {
    ThrowBadValue(path.string(), "a read error (" + std::string(std::strerror(errno)) + ")",
                  "a readable file");
  }
  return bytes;
}

}  // namespace

std::string ReadTextFile(const std::filesystem::path& path, std::size_t max_bytes) {
  const std::string expected = "a UTF-8 text file";
  std::string text = ReadBounded(path, max_bytes, expected, /*text_only=*/true);
  const std::size_t nul = text.find('\0');
  if (nul != std::string::npos) {
    ThrowBadValue(path.string(), "binary data (a NUL byte at offset " + std::to_string(nul) + ")",
                  expected);
  }
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);
  return text;
}

std::string ReadBinaryFile(const std::filesystem::path& path, std::size_t max_bytes) {
  return ReadBounded(path, max_bytes, "a file", /*text_only=*/false);
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
      ThrowBadValue(where, std::to_string(fields.size()) + " fields (" + Quote(content) + ")",
                    layout);
    }
    row(where, fields, line_number);
  }
}

}  // namespace mmh
