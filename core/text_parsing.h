// Small helpers for line-oriented text formats, shared by the TUM and CSV readers.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mmh {

// Reads a whole text file; throws InputError naming the path if it cannot be read.
std::string ReadTextFile(const std::filesystem::path& path);

// Splits on any run of the given delimiter characters, dropping empty fields.
std::vector<std::string_view> SplitFields(std::string_view line, std::string_view delimiters);

// Splits a CSV line on every comma, keeping empty fields ("a,,b" has three fields).
std::vector<std::string_view> SplitCsvFields(std::string_view line);

// Parses a complete double (no trailing characters); false if it is not one.
bool ParseDouble(std::string_view text, double* value);

// Removes leading and trailing white space (including '\r').
std::string_view Trim(std::string_view text);

}  // namespace mmh
