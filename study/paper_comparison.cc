#include "study/paper_comparison.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/error.h"

namespace mmh::study {
namespace {

const nlohmann::json& Check(const nlohmann::json& paper, const std::string& id) {
  if (paper.contains("checks") && paper["checks"].is_array()) {
    for (const auto& check : paper["checks"]) {
      if (check.value("id", "") == id) return check;
    }
  }
  throw InputError("paper_reported.json: no check with id '" + id +
                   "' (expected the paper's reported statistics, configs/paper_reported.json)");
}

std::string Field(const nlohmann::json& check, const std::string& key) {
  if (!check.contains(key)) {
    throw InputError("paper_reported.json, check '" + check.value("id", "?") + "': no field '" +
                     key + "'");
  }
  const auto& v = check[key];
  if (v.is_string()) return v.get<std::string>();
  return v.dump();
}

std::string Sig(double value, int digits = 4) {
  if (!std::isfinite(value)) return value > 0 ? "Inf" : (value < 0 ? "-Inf" : "NaN");
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
  return buffer;
}

std::string P(double p) {
  if (p < 0.0001) return "< 0.0001 (" + Sig(p, 2) + ")";
  return Sig(p, 4);
}

std::string PaperP(const nlohmann::json& check) {
  const std::string relation = check.value("p_relation", "=");
  return (relation == "=" ? "" : relation + " ") + Field(check, "p");
}

// Whether the paper's reported p is below alpha (a "<" relation with a bound at or below alpha, or
// an "=" value below it).
bool PaperSignificant(const nlohmann::json& check, double alpha) {
  const double p = std::stod(Field(check, "p"));
  const std::string relation = check.value("p_relation", "=");
  return relation == "<" ? p <= alpha : p < alpha;
}

std::string Same(bool paper_significant, double our_p, double alpha) {
  return paper_significant == (our_p < alpha) ? "yes" : "no";
}

const char* kNotComputed = "not computed";

}  // namespace

std::vector<ComparisonLine> CompareWithPaper(const StudyAnalysis& a, const nlohmann::json& paper,
                                             double alpha, int scorers) {
  std::vector<ComparisonLine> lines;
  const auto& s = a.summary;
  const auto& per_take = Check(paper, "comparisons_per_take");
  const auto& per_scorer = Check(paper, "comparisons_per_scorer");
  const std::string paper_animators = per_take.at("factors").at(0).dump();
  lines.push_back({"animators", paper_animators, std::to_string(s.animators), ""});
  lines.push_back({"scorers (animators among them)",
                   per_scorer.at("factors").at(0).dump() + " (" + paper_animators + ")",
                   std::to_string(scorers) + " (" + std::to_string(s.ranking_animators) + ")", ""});
  lines.push_back({"comparisons", Field(per_take, "reported"), std::to_string(s.comparisons), ""});

  // Rankings.
  const auto& fr = Check(paper, "rankings_friedman_p");
  if (a.rankings.friedman.result) {
    const auto& r = *a.rankings.friedman.result;
    lines.push_back({"Friedman chi2(" + Field(fr, "df1") + ")", Field(fr, "statistic"),
                     Sig(r.statistic) + " (df " + Sig(r.df) + ")", ""});
    lines.push_back({"Friedman p", PaperP(fr), P(r.p_value),
                     Same(PaperSignificant(fr, alpha), r.p_value, alpha)});
  } else {
    lines.push_back({"Friedman chi2", Field(fr, "statistic"), kNotComputed, ""});
  }

  // H1.
  const auto& h1 = Check(paper, "h1_t_p");
  const auto& h1s = Check(paper, "h1_t_from_mean_sd_n");
  lines.push_back({"H1 mean m (sd)", Field(h1s, "mean") + " (" + Field(h1s, "sd") + ")",
                   Sig(a.h1.mean_m) + " (" + Sig(a.h1.sd_m) + ")", ""});
  if (a.h1.t_test.result) {
    const auto& t = *a.h1.t_test.result;
    lines.push_back({"H1 t(" + Field(h1, "df1") + ")", Field(h1, "statistic"),
                     Sig(t.t) + " (df " + Sig(t.df) + ")", ""});
    lines.push_back({"H1 t-test p (one-tailed)", PaperP(h1), P(t.p_value),
                     Same(PaperSignificant(h1, alpha), t.p_value, alpha)});
    const double paper_d =
        (std::stod(Field(h1s, "mean")) - h1s.value("mu", 0.5)) / std::stod(Field(h1s, "sd"));
    lines.push_back({"H1 Cohen's d", "(" + Sig(paper_d, 3) + " from the printed mean and sd)",
                     Sig(t.cohens_d), ""});
  }
  const auto& h1c = Check(paper, "h1_chi_squared_p");
  lines.push_back({"H1 montage wins / comparisons",
                   "(" + Field(h1c, "proportion") + " of " + Field(h1c, "n") + ")",
                   std::to_string(a.h1.wins) + " / " + std::to_string(a.h1.comparisons), ""});
  if (a.h1.chi_squared.result) {
    const double p = a.h1.chi_squared.result->p_value;
    lines.push_back(
        {"H1 chi-squared p", PaperP(h1c), P(p), Same(PaperSignificant(h1c, alpha), p, alpha)});
  }
  if (a.h1.binomial.result) {
    lines.push_back({"H1 exact binomial p (one-tailed)", "(not reported)",
                     P(a.h1.binomial.result->p_value), ""});
  }

  // H2.
  const auto& h2 = Check(paper, "h2_t_p");
  const auto& h2s = Check(paper, "h2_t_from_mean_sd_n");
  int above = 0;
  for (const auto& [animator, b] : a.h2.b) above += b > a.options.all_takes_chance;
  // Paper, H2: "For all but 2 of the animators, the probability is higher than random chance."
  lines.push_back({"H2 animators with b_i > 0.125", "18 of 20 (\"all but 2\")",
                   std::to_string(above) + " of " + std::to_string(a.h2.b.size()), ""});
  if (a.h2.normality.result) {
    // Paper: "We first use a goodness of fit test and confirm that the b_i's follow a normal
    // distribution."
    const double p = a.h2.normality.result->p_value;
    lines.push_back({"H2 b_i normal (Shapiro-Wilk p)", "normal (test and p not reported)",
                     "W = " + Sig(a.h2.normality.result->w) + ", p = " + P(p),
                     p >= alpha ? "yes" : "no"});
  }
  if (a.h2.t_test.result) {
    const auto& t = *a.h2.t_test.result;
    lines.push_back({"H2 mean b (sd)", Field(h2s, "mean") + " (" + Field(h2s, "sd") + ")",
                     Sig(t.mean) + " (" + Sig(t.sd) + ")", ""});
    lines.push_back({"H2 t(" + Field(h2, "df1") + ")", Field(h2, "statistic"),
                     Sig(t.t) + " (df " + Sig(t.df) + ")", ""});
    lines.push_back({"H2 t-test p (one-tailed)", PaperP(h2), P(t.p_value),
                     Same(PaperSignificant(h2, alpha), t.p_value, alpha)});
  }

  // H3.
  const auto& h3 = Check(paper, "h3_f_p");
  if (a.h3.mixed_model.result) {
    const auto& f = a.h3.mixed_model.result->take_test;
    lines.push_back({"H3 F(" + Field(h3, "df1") + ", " + Field(h3, "df2") + ")",
                     Field(h3, "statistic"),
                     Sig(f.f) + " (df " + Sig(f.num_df) + ", " + Sig(f.den_df) + ")", ""});
    lines.push_back(
        {"H3 p", PaperP(h3), P(f.p_value), Same(PaperSignificant(h3, alpha), f.p_value, alpha)});
  }
  if (!a.h3.take_means.empty()) {
    std::string means;
    for (std::size_t k = 0; k < a.h3.take_means.size(); ++k) {
      means += (k ? ", " : "") + Sig(a.h3.take_means[k], 3);
    }
    lines.push_back({"H3 mean m by take", "(Figure 11, not printed)", means, ""});
  }
  if (a.h3.residual_normality.result) {
    // Paper: "running a goodness of fit test on the residuals and verify that they are indeed
    // normally distributed".
    const double p = a.h3.residual_normality.result->p_value;
    lines.push_back({"H3 residuals normal (Shapiro-Wilk p)", "normal (test and p not reported)",
                     P(p), p >= alpha ? "yes" : "no"});
  }

  // Segment Length Constraint.
  const auto& seg = Check(paper, "segment_constraint_cases");
  if (a.segment_constraint) {
    const auto& c = *a.segment_constraint;
    lines.push_back({"montages with quick transitions without the constraint",
                     Field(seg, "reported") + " of 20 (\"half\")",
                     std::to_string(c.animators_with_short_segments) + " of " +
                         std::to_string(c.animators.size()),
                     ""});
    // Paper: "the increase in the cost was found to be less than 1% in all the 10 cases".
    lines.push_back(
        {"their largest cost increase", "< 1 %",
         Sig(c.max_increase_percent, 3) + " % (mean " + Sig(c.mean_increase_percent, 3) + " %)",
         c.all_below_threshold ? "yes" : "no"});
  }
  return lines;
}

std::string ComparisonMarkdown(const std::vector<ComparisonLine>& lines) {
  std::ostringstream out;
  out << "| quantity | paper | simulated | same conclusion |\n|---|---|---|---|\n";
  for (const auto& l : lines) {
    out << "| " << l.quantity << " | " << l.paper << " | " << l.ours << " | " << l.same_conclusion
        << " |\n";
  }
  return out.str();
}

std::string ComparisonCsv(const std::vector<ComparisonLine>& lines) {
  const auto quote = [](const std::string& s) {
    std::string q = "\"";
    for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::ostringstream out;
  out << "quantity,paper,simulated,same_conclusion\n";
  for (const auto& l : lines) {
    out << quote(l.quantity) << ',' << quote(l.paper) << ',' << quote(l.ours) << ','
        << l.same_conclusion << '\n';
  }
  return out.str();
}

}  // namespace mmh::study
