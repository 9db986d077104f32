// Consistency audit of a paper's reported statistics (`mmh check-paper`), in the spirit of
// statcheck (Epskamp & Nuijten) and GRIM (Brown & Heathers 2017): every reported p-value is
// recomputed from its test statistic and degrees of freedom, every t from the reported mean, SD
// and N, every mean of binary outcomes is checked for granularity, and reported counts for
// arithmetic. Reported numbers are given as text ("26.88") so that their rounding is known: a
// check is consistent when some values that round to the reported ones satisfy it.
//
// The reported numbers live in a JSON file (configs/paper_reported.json), one entry per check,
// each quoting the paper:
//
//   {"paper": "...", "checks": [
//     {"id": "...", "kind": "p_from_statistic", "section": "...", "quote": "...",
//      "distribution": "chi_squared" | "t" | "f" | "z", "statistic": "26.88", "df1": 3,
//      "df2": 38 (F only), "tails": 1 | 2 (t and z; default 2), "p": "0.0001", "p_relation": "<" |
//      "=" | ">"},
//     {"kind": "t_from_summary", "mean": "0.6457", "sd": "0.133", "n": 20, "mu": 0.5,
//      "t": "5.18", "df": 19},
//     {"kind": "grim", "mean": "0.6457", "denominator": 420},
//     {"kind": "proportion_test", "proportion": "0.6457", "n": 420, "chance": 0.5,
//      "test": "chi_squared" | "binomial", "p": "0.0001", "p_relation": "<", "tails": 1 | 2},
//     {"kind": "product", "factors": [42, 10], "reported": 420}]}
//
// Unknown keys, missing keys and reported values given as numbers are InputErrors naming the
// entry and key.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace mmh::study {

// A number as printed in the paper: its value and its decimals (rounding half-width
// 0.5 * 10^-decimals).
struct ReportedValue {
  std::string text;
  double value = 0.0;
  int decimals = 0;

  double HalfWidth() const;
};

// Parses "26.88", "0.0001", "5" (not exponents); InputError naming `where` otherwise.
ReportedValue ParseReportedValue(const std::string& text, const std::string& where);

struct AuditCheck {
  std::string id;
  std::string kind;
  std::string section;              // where in the paper
  std::string quote;                // the paper's words
  std::optional<bool> quote_found;  // when the paper's text was given
  std::string reported;             // what the paper says, e.g. "t(19) = 5.18"
  std::string recomputed;           // what follows from the other numbers, with its rounding range
  bool consistent = false;
  nlohmann::json details;  // every number of the check

  nlohmann::json ToJson() const;
};

struct PaperAudit {
  std::string paper;
  std::string source;  // the JSON file
  std::vector<AuditCheck> checks;
  int consistent = 0;
  int inconsistent = 0;

  nlohmann::json ToJson() const;
  // The table printed by `mmh check-paper`.
  std::string Table() const;
};

// Audits the checks of `reported` (the JSON above; `source` names it in messages). With
// `paper_text`, each quote is also looked up in the paper (white space runs compared as one
// space).
PaperAudit AuditPaper(const nlohmann::json& reported, const std::string& source,
                      const std::optional<std::string>& paper_text = std::nullopt);

// Reads the JSON file (and the paper's text file, when given) and audits it.
PaperAudit AuditPaperFile(const std::filesystem::path& reported,
                          const std::optional<std::filesystem::path>& paper = std::nullopt);

}  // namespace mmh::study
