// The report's readers of mmh's output files: CSV tables (as strings, RFC 4180 quoting) and JSON
// files, with InputErrors naming the file, line and column; and a table as the page's data.
#pragma once

#include <cstddef>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace mmh::report {

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
};

// One line's fields ("a,b" and "" inside quotes).
std::vector<std::string> SplitQuotedCsvLine(const std::string& line);

// A CSV file with a header; blank lines skipped. A row with another number of fields, or an empty
// file, is an InputError naming the file (and line).
CsvTable ReadCsvTable(const std::filesystem::path& path);

// The index of column `name`; InputError naming the file when there is none.
int ColumnOf(const CsvTable& table, const std::string& name, const std::filesystem::path& path);

// The number at (row, column); InputError naming the file, line and column otherwise.
double NumberAt(const CsvTable& table, std::size_t row, int column,
                const std::filesystem::path& path);

// {"title", "file", "note", "columns", "rows"}: a CSV file as the page shows it.
nlohmann::json TableJson(const std::string& title, const std::filesystem::path& path,
                         const std::string& note = "");

// An SVG file as the page inlines it (an XML declaration dropped).
std::string InlineSvg(const std::filesystem::path& path);

}  // namespace mmh::report
