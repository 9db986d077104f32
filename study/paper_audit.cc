#include "study/paper_audit.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/json_text.h"
#include "core/text_parsing.h"
#include "stats/binomial_test.h"

namespace mmh::study {
namespace {

namespace bm = boost::math;

std::string Short(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

// One entry of the checks array, read strictly: unknown keys are errors, reported values must be
// strings.
class Entry {
 public:
  Entry(const nlohmann::json& json, std::string where, const std::vector<std::string>& allowed)
      : json_(json), where_(std::move(where)) {
    if (!json.is_object()) ThrowBadValue(where_, json.dump(), "an object");
    for (auto it = json.begin(); it != json.end(); ++it) {
      if (std::find(allowed.begin(), allowed.end(), it.key()) == allowed.end()) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        ThrowBadValue(where_ + "." + it.key(), "an unknown key", "one of " + list);
      }
    }
  }

  bool Has(const std::string& key) const { return json_.contains(key); }

  std::string Text(const std::string& key) const {
    const auto& v = At(key);
    if (!v.is_string()) ThrowBadValue(Where(key), v.dump(), "a string");
    return v.get<std::string>();
  }

  ReportedValue Reported(const std::string& key) const {
    const auto& v = At(key);
    if (!v.is_string()) {
      ThrowBadValue(Where(key), v.dump(),
                    "the number as printed in the paper, as a string (e.g. \"0.6457\"), so that "
                    "its rounding is known");
    }
    return ParseReportedValue(v.get<std::string>(), Where(key));
  }

  double Number(const std::string& key) const {
    const auto& v = At(key);
    double value = 0.0;
    if (v.is_number()) {
      value = v.get<double>();
    } else if (!v.is_string() || !ParseDouble(v.get<std::string>(), &value)) {
      ThrowBadValue(Where(key), v.dump(), "a number");
    }
    if (!std::isfinite(value)) ThrowBadValue(Where(key), v.dump(), "a finite number");
    return value;
  }

  double Number(const std::string& key, double fallback) const {
    return Has(key) ? Number(key) : fallback;
  }

  std::string Where(const std::string& key) const { return where_ + "." + key; }
  const std::string& where() const { return where_; }

 private:
  const nlohmann::json& At(const std::string& key) const {
    if (!json_.contains(key)) ThrowBadValue(Where(key), "nothing", "this key");
    return json_.at(key);
  }

  const nlohmann::json& json_;
  std::string where_;
};

struct Distribution {
  std::string name;  // chi_squared, t, f, z
  double df1 = 0.0;
  double df2 = 0.0;
  int tails = 2;

  // p-value of a statistic (upper tail; |stat| and `tails` for t and z).
  double P(double stat) const {
    if (name == "chi_squared") {
      return bm::cdf(
          bm::complement(bm::chi_squared_distribution<double>(df1), std::max(stat, 0.0)));
    }
    if (name == "f") {
      return bm::cdf(
          bm::complement(bm::fisher_f_distribution<double>(df1, df2), std::max(stat, 0.0)));
    }
    const double tail =
        name == "t"
            ? bm::cdf(bm::complement(bm::students_t_distribution<double>(df1), std::abs(stat)))
            : bm::cdf(bm::complement(bm::normal_distribution<double>(), std::abs(stat)));
    return tails == 2 ? std::min(1.0, 2.0 * tail) : tail;
  }

  std::string Describe(const std::string& stat) const {
    if (name == "chi_squared") return "chi2(" + Short(df1) + ") = " + stat;
    if (name == "f") return "F(" + Short(df1) + ", " + Short(df2) + ") = " + stat;
    if (name == "t") return "t(" + Short(df1) + ") = " + stat;
    return "z = " + stat;
  }
};

// Is the recomputed p range [low, high] compatible with the reported "p REL value"?
bool PCompatible(double low, double high, const std::string& relation, const ReportedValue& p) {
  if (relation == "<") return low < p.value;
  if (relation == ">") return high > p.value;
  return low <= p.value + p.HalfWidth() && high >= p.value - p.HalfWidth();
}

std::string ReadRelation(const Entry& e) {
  const std::string relation = e.Has("p_relation") ? e.Text("p_relation") : "=";
  if (relation != "<" && relation != "=" && relation != ">") {
    ThrowBadValue(e.Where("p_relation"), "'" + relation + "'", "\"<\", \"=\" or \">\"");
  }
  return relation;
}

int ReadTails(const Entry& e) {
  const double tails = e.Number("tails", 2.0);
  if (tails != 1.0 && tails != 2.0) ThrowBadValue(e.Where("tails"), Short(tails), "1 or 2");
  return static_cast<int>(tails);
}

const std::vector<std::string> kCommon = {"id", "kind", "section", "quote", "note"};

std::vector<std::string> With(std::vector<std::string> keys) {
  keys.insert(keys.end(), kCommon.begin(), kCommon.end());
  return keys;
}

void PFromStatistic(const Entry& e, AuditCheck* c) {
  Distribution d;
  d.name = e.Text("distribution");
  if (d.name != "chi_squared" && d.name != "t" && d.name != "f" && d.name != "z") {
    ThrowBadValue(e.Where("distribution"), "'" + d.name + "'",
                  "\"chi_squared\", \"t\", \"f\" or \"z\"");
  }
  if (d.name != "z") RequirePositive(d.df1 = e.Number("df1"), e.Where("df1"));
  if (d.name == "f") RequirePositive(d.df2 = e.Number("df2"), e.Where("df2"));
  if (d.name == "t" || d.name == "z") d.tails = ReadTails(e);
  const ReportedValue stat = e.Reported("statistic");
  const ReportedValue p = e.Reported("p");
  const std::string relation = ReadRelation(e);
  const double h = stat.HalfWidth();
  const double magnitude = (d.name == "t" || d.name == "z") ? std::abs(stat.value) : stat.value;
  const double p_at = d.P(magnitude);
  const double p_low = d.P(magnitude + h);
  const double p_high = d.P(std::max(magnitude - h, 0.0));
  c->consistent = PCompatible(p_low, p_high, relation, p);
  c->reported = d.Describe(stat.text) + ", p " + relation + " " + p.text +
                ((d.name == "t" || d.name == "z") ? (d.tails == 1 ? " (one-tailed)" : "") : "");
  c->recomputed = "p = " + Short(p_at) + " (" + Short(p_low) + " to " + Short(p_high) +
                  " within the statistic's rounding)";
  c->details = {{"distribution", d.name},
                {"df1", d.df1},
                {"df2", d.df2},
                {"tails", d.tails},
                {"statistic", stat.value},
                {"p_reported", p.value},
                {"p_relation", relation},
                {"p_recomputed", p_at},
                {"p_min", p_low},
                {"p_max", p_high}};
}

void TFromSummary(const Entry& e, AuditCheck* c) {
  const ReportedValue mean = e.Reported("mean");
  const ReportedValue sd = e.Reported("sd");
  const ReportedValue t = e.Reported("t");
  const double n = e.Number("n");
  const double mu = e.Number("mu");
  if (n < 2 || n != std::floor(n)) ThrowBadValue(e.Where("n"), Short(n), "an integer >= 2");
  RequirePositive(sd.value, e.Where("sd"));
  const double root_n = std::sqrt(n);
  const double t_at = (mean.value - mu) / (sd.value / root_n);
  double t_min = INFINITY;
  double t_max = -INFINITY;
  for (double m : {mean.value - mean.HalfWidth(), mean.value + mean.HalfWidth()}) {
    for (double s : {sd.value - sd.HalfWidth(), sd.value + sd.HalfWidth()}) {
      if (s <= 0.0) continue;
      const double v = (m - mu) / (s / root_n);
      t_min = std::min(t_min, v);
      t_max = std::max(t_max, v);
    }
  }
  const bool t_ok = t_min <= t.value + t.HalfWidth() && t_max >= t.value - t.HalfWidth();
  bool df_ok = true;
  std::string df_text;
  if (e.Has("df")) {
    const double df = e.Number("df");
    df_ok = df == n - 1.0;
    df_text = "(" + Short(df) + ")";
  }
  c->consistent = t_ok && df_ok;
  const double implied_sd = (mean.value - mu) * root_n / t.value;
  c->reported = "M = " + mean.text + ", SD = " + sd.text + ", N = " + Short(n) + ", t" + df_text +
                " = " + t.text;
  c->recomputed = "t(" + Short(n - 1.0) + ") = " + Short(t_at) + " (" + Short(t_min) + " to " +
                  Short(t_max) +
                  " within rounding); the reported t needs SD = " + Short(implied_sd) +
                  (df_ok ? "" : "; df should be N - 1");
  c->details = {{"mean", mean.value},
                {"sd", sd.value},
                {"n", n},
                {"mu", mu},
                {"t_reported", t.value},
                {"t_recomputed", t_at},
                {"t_min", t_min},
                {"t_max", t_max},
                {"df_consistent", df_ok},
                {"sd_implied_by_t", implied_sd}};
}

// Integers k in [0, n] with k / n rounding to `value`.
std::vector<long long> GrimCandidates(const ReportedValue& value, long long n) {
  const double h = value.HalfWidth();
  const double slack = 1e-9;
  const auto lo = static_cast<long long>(std::ceil((value.value - h) * n - slack));
  const auto hi = static_cast<long long>(std::floor((value.value + h) * n + slack));
  std::vector<long long> ks;
  for (long long k = std::max(lo, 0LL); k <= std::min(hi, n); ++k) ks.push_back(k);
  return ks;
}

long long ReadCount(const Entry& e, const std::string& key) {
  const double n = e.Number(key);
  if (n < 1 || n != std::floor(n) || n > 1e12) {
    ThrowBadValue(e.Where(key), Short(n), "a positive integer");
  }
  return static_cast<long long>(n);
}

void Grim(const Entry& e, AuditCheck* c) {
  const ReportedValue mean = e.Reported("mean");
  const long long n = ReadCount(e, "denominator");
  const std::vector<long long> ks = GrimCandidates(mean, n);
  c->consistent = !ks.empty();
  const auto nearest = static_cast<long long>(std::llround(mean.value * n));
  std::string near;
  for (long long k : {nearest - 1, nearest, nearest + 1}) {
    if (k < 0 || k > n) continue;
    near += (near.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(n) + " = " +
            Short(static_cast<double>(k) / n);
  }
  const bool cannot_fail = 1.0 / n <= 2.0 * mean.HalfWidth();
  c->reported = "mean " + mean.text + " of " + std::to_string(n) + " binary outcomes";
  c->recomputed = (ks.empty() ? "no k/" + std::to_string(n) + " rounds to " + mean.text
                              : std::to_string(ks.size()) + " value(s) k/" + std::to_string(n) +
                                    " round to " + mean.text) +
                  "; nearest: " + near +
                  (cannot_fail ? " (granularity finer than the rounding)" : "");
  nlohmann::json candidates = nlohmann::json::array();
  for (long long k : ks) candidates.push_back(k);
  c->details = {{"mean", mean.value},
                {"denominator", n},
                {"matching_numerators", candidates},
                {"granularity_finer_than_rounding", cannot_fail}};
}

void ProportionTest(const Entry& e, AuditCheck* c) {
  const ReportedValue proportion = e.Reported("proportion");
  const long long n = ReadCount(e, "n");
  const double chance = e.Number("chance", 0.5);
  if (!(chance > 0.0 && chance < 1.0)) {
    ThrowBadValue(e.Where("chance"), Short(chance), "a probability in (0, 1)");
  }
  const std::string test = e.Text("test");
  if (test != "chi_squared" && test != "binomial") {
    ThrowBadValue(e.Where("test"), "'" + test + "'", "\"chi_squared\" or \"binomial\"");
  }
  const int tails = ReadTails(e);
  const ReportedValue p = e.Reported("p");
  const std::string relation = ReadRelation(e);
  std::vector<long long> ks = GrimCandidates(proportion, n);
  const bool grim_ok = !ks.empty();
  if (ks.empty()) {
    const auto below = static_cast<long long>(std::floor(proportion.value * n));
    ks = {below, below + 1};
  }
  double p_min = INFINITY;
  double p_max = -INFINITY;
  nlohmann::json per = nlohmann::json::array();
  for (long long k : ks) {
    double pv = 0.0;
    if (test == "chi_squared") {
      const double e1 = n * chance;
      const double e2 = n * (1.0 - chance);
      const double x2 = (k - e1) * (k - e1) / e1 + (n - k - e2) * (n - k - e2) / e2;
      pv = bm::cdf(bm::complement(bm::chi_squared_distribution<double>(1.0), x2));
    } else {
      stats::BinomialTestOptions options;
      options.p = chance;
      options.alternative = tails == 2                             ? stats::Alternative::kTwoSided
                            : static_cast<double>(k) / n >= chance ? stats::Alternative::kGreater
                                                                   : stats::Alternative::kLess;
      pv = stats::BinomialTest(k, n, options).p_value;
    }
    p_min = std::min(p_min, pv);
    p_max = std::max(p_max, pv);
    per.push_back({{"successes", k}, {"p", pv}});
  }
  c->consistent = PCompatible(p_min, p_max, relation, p);
  c->reported = "proportion " + proportion.text + " of " + std::to_string(n) + ", " + test + " p " +
                relation + " " + p.text;
  c->recomputed = "p = " + Short(p_min) + (p_max != p_min ? " to " + Short(p_max) : "") + " for " +
                  std::to_string(ks.front()) +
                  (ks.size() > 1 ? ".." + std::to_string(ks.back()) : "") + " successes" +
                  (grim_ok ? "" : " (the proportion itself fails GRIM)");
  c->details = {{"proportion", proportion.value},
                {"n", n},
                {"chance", chance},
                {"test", test},
                {"tails", tails},
                {"candidates", per},
                {"p_reported", p.value},
                {"p_relation", relation}};
}

std::string NormalizeSpace(const std::string& text) {
  std::string out;
  bool space = false;
  for (char ch : text) {
    if (std::isspace(static_cast<unsigned char>(ch))) {
      space = true;
      continue;
    }
    if (space && !out.empty()) out += ' ';
    space = false;
    out += ch;
  }
  return out;
}

}  // namespace

double ReportedValue::HalfWidth() const { return 0.5 * std::pow(10.0, -decimals); }

ReportedValue ParseReportedValue(const std::string& text, const std::string& where) {
  ReportedValue r;
  r.text = text;
  const std::string_view t = Trim(text);
  bool digits = false;
  std::size_t i = 0;
  if (i < t.size() && (t[i] == '-' || t[i] == '+')) ++i;
  for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i) digits = true;
  if (i < t.size() && t[i] == '.') {
    ++i;
    for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i) {
      digits = true;
      ++r.decimals;
    }
  }
  if (!digits || i != t.size() || !ParseDouble(t, &r.value)) {
    ThrowBadValue(where, "'" + text + "'", "a number as printed, e.g. \"26.88\" (no exponent)");
  }
  return r;
}

nlohmann::json AuditCheck::ToJson() const {
  return {{"id", id},
          {"kind", kind},
          {"section", section},
          {"quote", quote},
          {"quote_found", quote_found ? nlohmann::json(*quote_found) : nlohmann::json(nullptr)},
          {"reported", reported},
          {"recomputed", recomputed},
          {"consistent", consistent},
          {"details", details}};
}

nlohmann::json PaperAudit::ToJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : checks) list.push_back(c.ToJson());
  return {{"paper", paper},
          {"source", source},
          {"consistent", consistent},
          {"inconsistent", inconsistent},
          {"checks", list}};
}

std::string PaperAudit::Table() const {
  std::size_t id_width = 2;
  std::size_t reported_width = 8;
  for (const auto& c : checks) {
    id_width = std::max(id_width, c.id.size());
    reported_width = std::max(reported_width, c.reported.size());
  }
  const auto pad = [](const std::string& s, std::size_t w) {
    return s + std::string(w > s.size() ? w - s.size() : 0, ' ');
  };
  std::ostringstream out;
  out << pad("verdict", 13) << "  " << pad("id", id_width) << "  "
      << pad("reported", reported_width) << "  recomputed\n";
  for (const auto& c : checks) {
    out << pad(c.consistent ? "consistent" : "INCONSISTENT", 13) << "  " << pad(c.id, id_width)
        << "  " << pad(c.reported, reported_width) << "  " << c.recomputed
        << (c.quote_found && !*c.quote_found ? "  [quote not found in the paper]" : "") << "\n";
  }
  out << consistent << " consistent, " << inconsistent << " inconsistent (" << paper << ")\n";
  return out.str();
}

PaperAudit AuditPaper(const nlohmann::json& reported, const std::string& source,
                      const std::optional<std::string>& paper_text) {
  const Entry top(reported, source, {"paper", "source", "checks", "note"});
  PaperAudit audit;
  audit.source = source;
  audit.paper = top.Has("paper") ? top.Text("paper") : "";
  if (!reported.contains("checks") || !reported["checks"].is_array()) {
    ThrowBadValue(source + ".checks",
                  reported.contains("checks") ? reported["checks"].dump() : "nothing",
                  "an array of checks");
  }
  const std::optional<std::string> paper =
      paper_text ? std::optional<std::string>(NormalizeSpace(*paper_text)) : std::nullopt;
  std::set<std::string> ids;
  for (std::size_t i = 0; i < reported["checks"].size(); ++i) {
    const nlohmann::json& json = reported["checks"][i];
    const std::string where = source + ": checks[" + std::to_string(i) + "]";
    if (!json.is_object() || !json.contains("kind") || !json["kind"].is_string()) {
      ThrowBadValue(where + ".kind",
                    json.is_object() && json.contains("kind") ? json["kind"].dump() : "nothing",
                    "\"p_from_statistic\", \"t_from_summary\", \"grim\", \"proportion_test\" or "
                    "\"product\"");
    }
    AuditCheck c;
    c.kind = json["kind"].get<std::string>();
    if (c.kind == "p_from_statistic") {
      const Entry e(json, where,
                    With({"distribution", "statistic", "df1", "df2", "tails", "p", "p_relation"}));
      PFromStatistic(e, &c);
    } else if (c.kind == "t_from_summary") {
      const Entry e(json, where, With({"mean", "sd", "n", "mu", "t", "df"}));
      TFromSummary(e, &c);
    } else if (c.kind == "grim") {
      const Entry e(json, where, With({"mean", "denominator"}));
      Grim(e, &c);
    } else if (c.kind == "proportion_test") {
      const Entry e(json, where,
                    With({"proportion", "n", "chance", "test", "tails", "p", "p_relation"}));
      ProportionTest(e, &c);
    } else if (c.kind == "product") {
      const Entry e(json, where, With({"factors", "reported"}));
      if (!json.contains("factors") || !json["factors"].is_array() || json["factors"].empty()) {
        ThrowBadValue(e.Where("factors"),
                      json.contains("factors") ? json["factors"].dump() : "nothing",
                      "a non-empty array of numbers");
      }
      double product = 1.0;
      std::string text;
      for (const auto& f : json["factors"]) {
        if (!f.is_number()) ThrowBadValue(e.Where("factors"), f.dump(), "numbers");
        product *= f.get<double>();
        text += (text.empty() ? "" : " x ") + Short(f.get<double>());
      }
      const double value = e.Number("reported");
      c.consistent = product == value;
      c.reported = text + " = " + Short(value);
      c.recomputed = text + " = " + Short(product);
      c.details = {{"factors", json["factors"]}, {"product", product}, {"reported", value}};
    } else {
      ThrowBadValue(where + ".kind", "'" + c.kind + "'",
                    "\"p_from_statistic\", \"t_from_summary\", \"grim\", \"proportion_test\" or "
                    "\"product\"");
    }
    c.id = json.value("id", "");
    if (c.id.empty() || !json["id"].is_string()) {
      ThrowBadValue(where + ".id", json.contains("id") ? json["id"].dump() : "nothing",
                    "a non-empty string naming the check");
    }
    if (!ids.insert(c.id).second) ThrowBadValue(where + ".id", c.id, "a unique id");
    for (const char* key : {"section", "quote"}) {
      if (!json.contains(key) || !json[key].is_string() || json[key].get<std::string>().empty()) {
        ThrowBadValue(where + "." + key, json.contains(key) ? json[key].dump() : "nothing",
                      "the paper's words and where they are (every check quotes the paper)");
      }
    }
    c.section = json["section"].get<std::string>();
    c.quote = json["quote"].get<std::string>();
    if (paper) c.quote_found = paper->find(NormalizeSpace(c.quote)) != std::string::npos;
    (c.consistent ? audit.consistent : audit.inconsistent) += 1;
    audit.checks.push_back(std::move(c));
  }
  return audit;
}

PaperAudit AuditPaperFile(const std::filesystem::path& reported,
                          const std::optional<std::filesystem::path>& paper) {
  const std::string text = ReadTextFile(reported);
  // Repeated keys are errors, syntax errors name the line and column (core/json_text.h).
  const nlohmann::json json = ParseJsonText(text, reported.string());
  std::optional<std::string> paper_text;
  if (paper) paper_text = ReadTextFile(*paper);
  return AuditPaper(json, reported.string(), paper_text);
}

}  // namespace mmh::study
