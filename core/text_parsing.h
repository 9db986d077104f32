// Small helpers for line-oriented text formats, shared by the TUM and CSV readers.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace mmh {

// Largest text file read by default (trajectories of hours at 30 Hz are a few hundred MB less).
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{1} << 30;

// Reads a whole UTF-8 (or ASCII) text file; throws InputError naming the path if it cannot be
// read, if it is longer than `max_bytes` (so /dev/zero or a FIFO cannot exhaust memory), if it is
// UTF-16 or UTF-32 (a byte-order mark or NUL bytes) or binary (a NUL byte). A UTF-8 byte-order
// mark at the start is dropped (editors on Windows write one).
std::string ReadTextFile(const std::filesystem::path& path,
                         std::size_t max_bytes = kMaxTextFileBytes);

// Reads a whole file of any content (a .glb, an image) with the same errors and size bound as
// ReadTextFile, without the text checks.
std::string ReadBinaryFile(const std::filesystem::path& path,
                           std::size_t max_bytes = kMaxTextFileBytes);

// Splits on any run of the given delimiter characters, dropping empty fields.
std::vector<std::string_view> SplitFields(std::string_view line, std::string_view delimiters);

// Splits a CSV line on every comma, keeping empty fields ("a,,b" has three fields).
std::vector<std::string_view> SplitCsvFields(std::string_view line);

// Parses a complete double (no trailing characters); false if it is not one.
bool ParseDouble(std::string_view text, double* value);

// Removes leading and trailing white space (including '\r').
std::string_view Trim(std::string_view text);

// The data rows of a whitespace-separated text file (TUM trajectories and lists): calls
// row(where, fields, line) for every line that is not blank or a '#' comment, where = "path:line".
// A row with another number of fields than `field_count` is an InputError naming the file and
// line, the row and `layout` (e.g. "8 fields: timestamp tx ty tz qx qy qz qw").
void ForEachDataRow(
    const std::filesystem::path& path, std::size_t field_count, const std::string& layout,
    const std::function<void(const std::string& where, const std::vector<std::string_view>& fields,
                             int line)>& row);

}  // namespace mmh
