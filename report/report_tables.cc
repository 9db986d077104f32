#include "report/report_tables.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/text_parsing.h"

namespace mmh::report {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<std::string> SplitQuotedCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  return fields;
}

CsvTable ReadCsvTable(const fs::path& path) {
  const std::string text = ReadTextFile(path);
  CsvTable table;
  std::size_t start = 0;
  int line_number = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (Trim(line).empty()) continue;
    std::vector<std::string> fields = SplitQuotedCsvLine(line);
    if (table.columns.empty()) {
      table.columns = std::move(fields);
    } else if (fields.size() != table.columns.size()) {
      ThrowBadValue(path.string() + ":" + std::to_string(line_number),
                    std::to_string(fields.size()) + " fields",
                    std::to_string(table.columns.size()) + " fields as in the header");
    } else {
      table.rows.push_back(std::move(fields));
    }
  }
  if (table.columns.empty()) ThrowBadValue(path.string(), "an empty file", "a CSV with a header");
  return table;
}

int ColumnOf(const CsvTable& table, const std::string& name, const fs::path& path) {
  const auto it = std::find(table.columns.begin(), table.columns.end(), name);
  if (it == table.columns.end()) ThrowBadValue(path.string(), "no column " + name, "mmh's layout");
  return static_cast<int>(it - table.columns.begin());
}

double NumberAt(const CsvTable& table, std::size_t row, int column, const fs::path& path) {
  double value = 0.0;
  if (!ParseDouble(table.rows[row][column], &value)) {
    ThrowBadValue(path.string() + ":" + std::to_string(row + 2) + " " + table.columns[column],
                  table.rows[row][column], "a number");
  }
  return value;
}

json TableJson(const std::string& title, const fs::path& path, const std::string& note) {
  const CsvTable table = ReadCsvTable(path);
  return {{"title", title}, {"file", path.filename().string()}, {"note", note},
          {"columns", table.columns}, {"rows", table.rows}};
}

std::string InlineSvg(const fs::path& path) {
  std::string svg = ReadTextFile(path);
  if (svg.rfind("<?xml", 0) == 0) svg = svg.substr(svg.find("?>") + 2);
  return svg;
}

}  // namespace mmh::report
