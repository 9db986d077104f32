#include "study/study_data.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/error_text.h"
#include "core/text_parsing.h"
#include "stats/descriptive.h"

namespace mmh::study {
namespace {

// A CSV file with a header row: the columns are found by name (any order); a missing required
// or an unknown column is an error; `optional` columns may be absent (their fields are then
// empty). Blank lines and lines starting with '#' are skipped.
class CsvTable {
 public:
  CsvTable(const std::filesystem::path& path, std::vector<std::string> columns,
           const std::vector<std::string>& optional = {})
      : source_(path.string()), required_(columns.size()) {
    columns.insert(columns.end(), optional.begin(), optional.end());
    const std::string text = ReadTextFile(path);
    std::istringstream lines(text);
    std::string line;
    int number = 0;
    bool header_seen = false;
    while (std::getline(lines, line)) {
      ++number;
      const std::string_view content = Trim(line);
      if (content.empty() || content.front() == '#') continue;
      const std::vector<std::string_view> fields = SplitCsvFields(content);
      if (!header_seen) {
        ReadHeader(fields, columns, number, std::string(content));
        header_seen = true;
        continue;
      }
      if (fields.size() != header_.size()) {
        ThrowBadValue(source_ + ":" + std::to_string(number),
                      std::to_string(fields.size()) + " fields ('" + std::string(content) + "')",
                      std::to_string(header_.size()) + " fields: " + Join(header_));
      }
      Row row;
      row.line = number;
      row.fields.resize(columns.size());
      for (std::size_t c = 0; c < header_.size(); ++c) {
        const std::string field(fields[c]);
        if (!field.empty() && (field.front() == '"' || field.front() == '\'')) {
          ThrowBadValue(Where(number, header_[c]), "'" + field + "'",
                        "an unquoted value (quoted CSV fields are not supported)");
        }
        row.fields[index_of_[c]] = field;
      }
      rows_.push_back(std::move(row));
    }
    if (!header_seen) {
      ThrowBadValue(source_, "an empty file", "a header line '" + Join(columns) + "' and rows");
    }
  }

  struct Row {
    int line = 0;
    std::vector<std::string> fields;  // in the order of the requested columns
  };
  const std::vector<Row>& rows() const { return rows_; }
  bool Has(const std::string& column) const {
    return std::find(header_.begin(), header_.end(), column) != header_.end();
  }
  const std::string& source() const { return source_; }

  std::string Where(int line, const std::string& column) const {
    return source_ + ":" + std::to_string(line) + ", column '" + column + "'";
  }

 private:
  static std::string Join(const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
    return out;
  }

  void ReadHeader(const std::vector<std::string_view>& fields,
                  const std::vector<std::string>& columns, int line, const std::string& content) {
    const std::string where = source_ + ":" + std::to_string(line);
    std::set<std::string> seen;
    for (const auto& f : fields) {
      const std::string name(f);
      std::size_t found = columns.size();
      for (std::size_t c = 0; c < columns.size(); ++c) found = columns[c] == name ? c : found;
      if (found == columns.size()) {
        ThrowBadValue(where, "the column '" + name + "' in the header '" + content + "'",
                      "the columns " + Join(columns) + " (in any order)");
      }
      if (!seen.insert(name).second) {
        ThrowBadValue(where, "the column '" + name + "' twice", "each column once");
      }
      header_.push_back(name);
      index_of_.push_back(found);
    }
    for (std::size_t k = 0; k < required_; ++k) {
      const std::string& c = columns[k];
      if (!seen.count(c)) {
        ThrowBadValue(where, "the header '" + content + "' without the column '" + c + "'",
                      "the columns " + Join(columns) + " (in any order)");
      }
    }
  }

  std::string source_;
  std::size_t required_ = 0;           // the first required_ columns must be present
  std::vector<std::string> header_;    // column names in file order
  std::vector<std::size_t> index_of_;  // file column -> requested column
  std::vector<Row> rows_;
};

std::string ParseId(const std::string& text, const std::string& where) {
  if (text.empty()) ThrowBadValue(where, "an empty value", "a non-empty ID");
  return text;
}

double ParseFinite(const std::string& text, const std::string& where, const std::string& what) {
  double value = 0.0;
  if (!ParseDouble(text, &value) || !std::isfinite(value)) {
    ThrowBadValue(where, "'" + text + "'", what);
  }
  return value;
}

int ParseInt(const std::string& text, const std::string& where, int min, const std::string& what) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end || value < min) {
    ThrowBadValue(where, "'" + text + "'", what);
  }
  return value;
}

std::string WhereRow(const std::string& source, int line) {
  return line > 0 ? source + ":" + std::to_string(line) : source;
}

// IDs go into CSV files unquoted: no separators, quotes, line breaks or surrounding blanks.
void CheckId(const std::string& id, const std::string& where) {
  const bool bad = id.empty() || id.find_first_of(",\"'\n\r") != std::string::npos ||
                   Trim(id).size() != id.size();
  if (bad) {
    ThrowBadValue(where, "'" + id + "'",
                  "a non-empty ID without commas, quotes, line breaks or surrounding blanks");
  }
}

}  // namespace

int TakeNumberOfItem(const std::string& item) {
  if (item.size() < 5 || item.compare(0, 4, "take") != 0) return 0;
  int k = 0;
  const char* begin = item.data() + 4;
  const char* end = item.data() + item.size();
  const auto [ptr, ec] = std::from_chars(begin, end, k);
  if (ec != std::errc() || ptr != end || k < 1 || *begin == '0' || *begin == '+') return 0;
  return k;
}

StudyData ReadStudyData(const std::filesystem::path& dir, const StudyDataOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    ThrowBadValue(dir.string(), "not a folder", "a folder with rankings.csv and comparisons.csv");
  }
  StudyData data;
  {
    const CsvTable table(dir / kRankingsFile, {"animator", "item", "rank"});
    data.rankings_source = table.source();
    for (const auto& row : table.rows()) {
      RankingRow r;
      r.line = row.line;
      r.animator = ParseId(row.fields[0], table.Where(row.line, "animator"));
      r.item = row.fields[1];
      if (r.item != kMontageItem && TakeNumberOfItem(r.item) == 0) {
        ThrowBadValue(table.Where(row.line, "item"), "'" + r.item + "'",
                      "'montage' or 'take<k>' with k = 1, 2, ... (e.g. take1)");
      }
      r.rank =
          ParseFinite(row.fields[2], table.Where(row.line, "rank"), "a rank 1, 2, ... (1 = best)");
      data.rankings.push_back(r);
    }
  }
  {
    const CsvTable table(dir / kComparisonsFile,
                         {"scorer", "animator", "take", "montage_preferred"});
    data.comparisons_source = table.source();
    for (const auto& row : table.rows()) {
      ComparisonRow c;
      c.line = row.line;
      c.scorer = ParseId(row.fields[0], table.Where(row.line, "scorer"));
      c.animator = ParseId(row.fields[1], table.Where(row.line, "animator"));
      c.take = ParseInt(row.fields[2], table.Where(row.line, "take"), 1,
                        "a take number 1, 2, ... (recording order)");
      const std::string& preferred = row.fields[3];
      if (preferred != "0" && preferred != "1") {
        ThrowBadValue(table.Where(row.line, "montage_preferred"), "'" + preferred + "'",
                      "1 (the montage was preferred) or 0 (the take was preferred)");
      }
      c.montage_preferred = preferred == "1";
      data.comparisons.push_back(c);
    }
  }
  if (std::filesystem::exists(dir / kSegmentCostsFile, ec)) {
    const CsvTable table(
        dir / kSegmentCostsFile,
        {"animator", "cost_unconstrained", "cost_constrained", "short_segments_unconstrained"},
        {"reference_frames"});
    data.segment_costs_source = table.source();
    for (const auto& row : table.rows()) {
      SegmentCostRow s;
      s.line = row.line;
      s.animator = ParseId(row.fields[0], table.Where(row.line, "animator"));
      s.cost_unconstrained =
          ParseFinite(row.fields[1], table.Where(row.line, "cost_unconstrained"), "a finite cost");
      s.cost_constrained =
          ParseFinite(row.fields[2], table.Where(row.line, "cost_constrained"), "a finite cost");
      s.short_segments_unconstrained = ParseInt(
          row.fields[3], table.Where(row.line, "short_segments_unconstrained"), 0, "a count >= 0");
      if (table.Has("reference_frames")) {
        s.reference_frames = ParseInt(row.fields[4], table.Where(row.line, "reference_frames"), 1,
                                      "a frame count >= 1");
      }
      data.segment_costs.push_back(s);
    }
  }
  ValidateStudyData(data, options);
  return data;
}

namespace {

// Each animator's ranking rows, by animator.
using RowsByAnimator = std::map<std::string, std::vector<const RankingRow*>>;

// Rankings, row by row: ids, items, finite ranks, one rank per (animator, item).
RowsByAnimator CheckRankingRows(const StudyData& data, std::set<std::string>* items) {
  RowsByAnimator by_animator;
  std::map<std::pair<std::string, std::string>, int> seen;
  for (const auto& r : data.rankings) {
    const std::string where = WhereRow(data.rankings_source, r.line);
    CheckId(r.animator, where + ", column 'animator'");
    if (r.item != kMontageItem && TakeNumberOfItem(r.item) == 0) {
      ThrowBadValue(where + ", column 'item'", "'" + r.item + "'", "'montage' or 'take<k>'");
    }
    if (!std::isfinite(r.rank)) {
      ThrowBadValue(where + ", column 'rank'", FormatNumber(r.rank), "a finite rank");
    }
    const auto [it, inserted] = seen.emplace(std::make_pair(r.animator, r.item), r.line);
    if (!inserted) {
      ThrowBadValue(where,
                    "a second rank of item '" + r.item + "' by animator '" + r.animator +
                        "' (first on line " + std::to_string(it->second) + ")",
                    "one rank per animator and item");
    }
    by_animator[r.animator].push_back(&r);
    items->insert(r.item);
  }
  if (data.rankings.empty()) {
    ThrowBadValue(data.rankings_source, "no rows", "one row per animator and ranked item");
  }
  if (items->size() < 2) {
    ThrowBadValue(data.rankings_source, std::to_string(items->size()) + " ranked item",
                  "at least 2 items (the takes and the montage)");
  }
  return by_animator;
}

// Every animator ranks the same items, and their ranks are 1..K (mid-ranks for ties if allowed).
void CheckEachAnimatorsRanking(const StudyData& data, const RowsByAnimator& by_animator,
                               const std::set<std::string>& items,
                               const StudyDataOptions& options) {
  std::string item_list;
  for (const auto& i : items) item_list += (item_list.empty() ? "" : ", ") + i;
  const double k = static_cast<double>(items.size());
  for (const auto& [animator, rows] : by_animator) {
    const std::string where = WhereRow(data.rankings_source, rows.front()->line);
    if (rows.size() != items.size()) {
      std::string mine;
      for (const auto* r : rows) mine += (mine.empty() ? "" : ", ") + r->item;
      ThrowBadValue(where,
                    "animator '" + animator + "' ranking " + std::to_string(rows.size()) +
                        " items (" + mine + ")",
                    "the " + std::to_string(items.size()) + " items every animator ranks (" +
                        item_list + ")");
    }
    std::vector<double> ranks;
    std::string rank_list;
    for (const auto* r : rows) {
      ranks.push_back(r->rank);
      rank_list += (rank_list.empty() ? "" : ", ") + FormatNumber(r->rank);
    }
    bool valid = true;
    if (options.allow_tied_ranks) {
      valid = stats::AverageRanks(ranks) == ranks;
    } else {
      std::vector<double> sorted = ranks;
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t i = 0; i < sorted.size(); ++i) valid = valid && sorted[i] == i + 1.0;
    }
    if (!valid) {
      ThrowBadValue(
          where + ", column 'rank'", "ranks " + rank_list + " from animator '" + animator + "'",
          options.allow_tied_ranks
              ? "the ranks 1.." + FormatNumber(k) + " with ties as mid-ranks"
              : "a permutation of 1.." + FormatNumber(k) + " (set allow_tied_ranks for mid-ranks)");
    }
  }
}

// Comparisons: unique (scorer, animator, take); takes 1..K all present.
void CheckComparisons(const StudyData& data) {
  if (data.comparisons.empty()) {
    ThrowBadValue(data.comparisons_source, "no rows", "one row per binary comparison");
  }
  std::map<std::tuple<std::string, std::string, int>, int> seen;
  std::set<int> takes;
  for (const auto& c : data.comparisons) {
    const std::string where = WhereRow(data.comparisons_source, c.line);
    CheckId(c.scorer, where + ", column 'scorer'");
    CheckId(c.animator, where + ", column 'animator'");
    if (c.take < 1) {
      ThrowBadValue(where + ", column 'take'", std::to_string(c.take), "a take number >= 1");
    }
    const auto [it, inserted] = seen.emplace(std::make_tuple(c.scorer, c.animator, c.take), c.line);
    if (!inserted) {
      ThrowBadValue(where,
                    "a second comparison by scorer '" + c.scorer + "' of animator '" + c.animator +
                        "' take " + std::to_string(c.take) + " (first on line " +
                        std::to_string(it->second) + ")",
                    "each scorer compares a take with its montage at most once");
    }
    takes.insert(c.take);
  }
  const int max_take = *takes.rbegin();
  for (int t = 1; t <= max_take; ++t) {
    if (!takes.count(t)) {
      ThrowBadValue(
          data.comparisons_source + ", column 'take'",
          "takes up to " + std::to_string(max_take) + " but never take " + std::to_string(t),
          "takes numbered 1..K, each compared at least once");
    }
  }
}

// Segment costs: finite, the constrained optimum not below the unconstrained, one row per
// animator of the rankings.
void CheckSegmentCosts(const StudyData& data, const RowsByAnimator& by_animator) {
  std::map<std::string, int> cost_lines;
  for (const auto& s : data.segment_costs) {
    const std::string where = WhereRow(data.segment_costs_source, s.line);
    CheckId(s.animator, where + ", column 'animator'");
    // Costs may be negative (the compositor's data cost is -a'(t)); they must be finite.
    RequireFinite(s.cost_unconstrained, where + ", column 'cost_unconstrained'");
    RequireFinite(s.cost_constrained, where + ", column 'cost_constrained'");
    if (s.short_segments_unconstrained < 0) {
      ThrowBadValue(where + ", column 'short_segments_unconstrained'",
                    std::to_string(s.short_segments_unconstrained), "a count >= 0");
    }
    if (s.cost_constrained < s.cost_unconstrained) {
      ThrowBadValue(where + ", column 'cost_constrained'", FormatNumber(s.cost_constrained),
                    "at least cost_unconstrained = " + FormatNumber(s.cost_unconstrained) +
                        " (a constraint cannot lower the optimum)");
    }
    // A cost row of an animator who ranked nothing is a typo or another study's row: the
    // segment-constraint analysis would silently use it.
    if (!by_animator.count(s.animator)) {
      ThrowBadValue(where + ", column 'animator'", Quote(s.animator),
                    "an animator of " + data.rankings_source + " (" +
                        std::to_string(by_animator.size()) + " animators)");
    }
    const auto [it, inserted] = cost_lines.emplace(s.animator, s.line);
    if (!inserted) {
      ThrowBadValue(where,
                    "a second cost row for animator '" + s.animator + "' (first on line " +
                        std::to_string(it->second) + ")",
                    "one row per animator");
    }
  }
}

}  // namespace

void ValidateStudyData(const StudyData& data, const StudyDataOptions& options) {
  std::set<std::string> items;
  const RowsByAnimator by_animator = CheckRankingRows(data, &items);
  CheckEachAnimatorsRanking(data, by_animator, items, options);
  CheckComparisons(data);
  CheckSegmentCosts(data, by_animator);
}

std::string RankingsToCsv(const std::vector<RankingRow>& rows) {
  std::string out = "animator,item,rank\n";
  for (const auto& r : rows) out += r.animator + "," + r.item + "," + FormatNumber(r.rank) + "\n";
  return out;
}

std::string ComparisonsToCsv(const std::vector<ComparisonRow>& rows) {
  std::string out = "scorer,animator,take,montage_preferred\n";
  for (const auto& c : rows) {
    out += c.scorer + "," + c.animator + "," + std::to_string(c.take) + "," +
           (c.montage_preferred ? "1" : "0") + "\n";
  }
  return out;
}

std::string SegmentCostsToCsv(const std::vector<SegmentCostRow>& rows) {
  // reference_frames (optional in the schema) only when every row knows it.
  const bool frames = !rows.empty() && std::all_of(rows.begin(), rows.end(), [](const auto& s) {
    return s.reference_frames > 0;
  });
  std::string out = "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained";
  out += frames ? ",reference_frames\n" : "\n";
  for (const auto& s : rows) {
    out += s.animator + "," + FormatNumber(s.cost_unconstrained) + "," +
           FormatNumber(s.cost_constrained) + "," + std::to_string(s.short_segments_unconstrained) +
           (frames ? "," + std::to_string(s.reference_frames) : std::string()) + "\n";
  }
  return out;
}

void WriteStudyData(const std::filesystem::path& dir, const StudyData& data) {
  ValidateStudyData(data, StudyDataOptions{.allow_tied_ranks = true});
  EnsureDirectory(dir);
  WriteFileAtomically(dir / kRankingsFile, RankingsToCsv(data.rankings));
  WriteFileAtomically(dir / kComparisonsFile, ComparisonsToCsv(data.comparisons));
  if (!data.segment_costs.empty()) {
    WriteFileAtomically(dir / kSegmentCostsFile, SegmentCostsToCsv(data.segment_costs));
  }
}

}  // namespace mmh::study
