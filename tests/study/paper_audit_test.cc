#include "study/paper_audit.h"

#include <gtest/gtest.h>

#include <set>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::study {
namespace {

using test_util::ErrorOf;

const std::filesystem::path kReported =
    std::filesystem::path(MMH_SOURCE_DIR) / "configs" / "paper_reported.json";
// shared/ lies beside the clone (/work/shared for /work/main; CI: beside the fresh clone).
const std::filesystem::path kPaper = std::filesystem::path(MMH_SOURCE_DIR).parent_path() /
                                     "shared" / "paper" / "motionmontage-chi2014.txt";

const AuditCheck& Find(const PaperAudit& audit, const std::string& id) {
  for (const auto& c : audit.checks) {
    if (c.id == id) return c;
  }
  throw std::runtime_error("no check " + id);
}

TEST(PaperAudit, ThePapersNumbers) {
  const PaperAudit audit = AuditPaperFile(kReported);
  EXPECT_EQ(audit.checks.size(), 12u);
  std::set<std::string> inconsistent;
  for (const auto& c : audit.checks) {
    if (!c.consistent) inconsistent.insert(c.id);
  }
  // The reported SDs do not give the reported t values, and 0.6457 is no multiple of 1/420; every
  // reported p follows from its statistic.
  EXPECT_EQ(inconsistent,
            (std::set<std::string>{"h1_t_from_mean_sd_n", "h1_mean_grim", "h2_t_from_mean_sd_n"}));
  EXPECT_EQ(audit.inconsistent, 3);
  EXPECT_EQ(audit.consistent, 9);

  // Recomputed values against R: pchisq(26.88, 3, lower.tail = FALSE), pt(5.18, 19, lower.tail =
  // FALSE), pt(4.555, 19, lower.tail = FALSE), pf(0.8277, 2, 38, lower.tail = FALSE),
  // (0.6457 - 0.5) / (0.133 / sqrt(20)), (0.299 - 0.125) / (0.126 / sqrt(20)).
  MMH_EXPECT_NEAR_R(Find(audit, "rankings_friedman_p").details["p_recomputed"].get<double>(),
                    6.2384336136197411e-06);
  MMH_EXPECT_NEAR_R(Find(audit, "h1_t_p").details["p_recomputed"].get<double>(),
                    2.6633651346742120e-05);
  MMH_EXPECT_NEAR_R(Find(audit, "h2_t_p").details["p_recomputed"].get<double>(),
                    1.0821730187235686e-04);
  MMH_EXPECT_NEAR_R(Find(audit, "h3_f_p").details["p_recomputed"].get<double>(),
                    4.4477869087019595e-01);
  MMH_EXPECT_NEAR_R(Find(audit, "h1_t_from_mean_sd_n").details["t_recomputed"].get<double>(),
                    4.8991745010784884);
  MMH_EXPECT_NEAR_R(Find(audit, "h2_t_from_mean_sd_n").details["t_recomputed"].get<double>(),
                    6.1758067949994189);
  // chisq.test(c(271, 149))$p.value: the nearest count below 0.6457 * 420.
  const auto& candidates = Find(audit, "h1_chi_squared_p").details["candidates"];
  ASSERT_EQ(candidates.size(), 2u);
  EXPECT_EQ(candidates[0]["successes"], 271);
  MMH_EXPECT_NEAR_R(candidates[0]["p"].get<double>(), 2.6328667493339517e-09);
}

TEST(PaperAudit, EveryQuoteIsInThePaper) {
  if (!std::filesystem::exists(kPaper)) GTEST_SKIP() << kPaper << " not present";
  const PaperAudit audit = AuditPaperFile(kReported, kPaper);
  for (const auto& c : audit.checks) {
    ASSERT_TRUE(c.quote_found.has_value());
    EXPECT_TRUE(*c.quote_found) << c.id << ": " << c.quote;
  }
}

nlohmann::json One(nlohmann::json check) {
  check["id"] = "x";
  check["section"] = "s";
  check["quote"] = "q";
  return {{"paper", "test"}, {"checks", {check}}};
}

AuditCheck Audit(const nlohmann::json& check) {
  return AuditPaper(One(check), "test.json").checks.at(0);
}

TEST(PaperAudit, PValueWithinTheRoundingOfTheStatistic) {
  // 2 * pt(-2.1, 10) = 0.0621 (R): "p = .06" is consistent, "p = .05" is not, "p < .05" is not.
  nlohmann::json check = {{"kind", "p_from_statistic"}, {"distribution", "t"}, {"df1", 10},
                          {"statistic", "2.1"},         {"p", "0.06"},         {"p_relation", "="}};
  EXPECT_TRUE(Audit(check).consistent);
  MMH_EXPECT_NEAR_R(Audit(check).details["p_recomputed"].get<double>(), 6.2077244202218468e-02);
  check["p"] = "0.05";
  EXPECT_FALSE(Audit(check).consistent);
  check["p_relation"] = "<";
  EXPECT_FALSE(Audit(check).consistent);
  // z = 1.96 -> p = 0.049996 (R: 2 * pnorm(-1.96)); "p < .05" holds; so does "p = .05".
  check = {{"kind", "p_from_statistic"},
           {"distribution", "z"},
           {"statistic", "1.96"},
           {"p", "0.05"},
           {"p_relation", "<"}};
  EXPECT_TRUE(Audit(check).consistent);
  // Rounding of the statistic counts: t(10) = 2.2 reported, p = 0.05 fits t in [2.15, 2.25].
  check = {{"kind", "p_from_statistic"},
           {"distribution", "t"},
           {"df1", 10},
           {"statistic", "2.2"},
           {"p", "0.05"}};
  EXPECT_TRUE(Audit(check).consistent);
}

TEST(PaperAudit, TFromSummaryAndDf) {
  // M = 1.5, SD = 1, N = 16, mu = 1: t = 2 exactly.
  nlohmann::json check = {{"kind", "t_from_summary"},
                          {"mean", "1.5"},
                          {"sd", "1.0"},
                          {"n", 16},
                          {"mu", 1},
                          {"t", "2.00"},
                          {"df", 15}};
  EXPECT_TRUE(Audit(check).consistent);
  check["df"] = 16;
  EXPECT_FALSE(Audit(check).consistent);
  check["df"] = 15;
  check["t"] = "2.50";
  EXPECT_FALSE(Audit(check).consistent);
  MMH_EXPECT_NEAR_R(Audit(check).details["sd_implied_by_t"].get<double>(), 0.8);
}

TEST(PaperAudit, Grim) {
  nlohmann::json check = {{"kind", "grim"}, {"mean", "0.6452"}, {"denominator", 420}};
  EXPECT_TRUE(Audit(check).consistent);  // 271 / 420 = 0.64524
  check["mean"] = "0.6457";
  EXPECT_FALSE(Audit(check).consistent);
  check = {{"kind", "grim"}, {"mean", "0.35"}, {"denominator", 20}};
  EXPECT_TRUE(Audit(check).consistent);  // 7 / 20 exactly
  check["mean"] = "0.37";
  EXPECT_FALSE(Audit(check).consistent);
}

TEST(PaperAudit, ProductAndBinomialProportion) {
  EXPECT_TRUE(Audit({{"kind", "product"}, {"factors", {42, 10}}, {"reported", 420}}).consistent);
  EXPECT_FALSE(Audit({{"kind", "product"}, {"factors", {42, 10}}, {"reported", 410}}).consistent);
  // 15 of 20 against 0.5, one-tailed exact binomial: p = 0.0207 (R: binom.test(15, 20, alternative
  // = "greater")).
  const AuditCheck c = Audit({{"kind", "proportion_test"},
                              {"proportion", "0.75"},
                              {"n", 20},
                              {"test", "binomial"},
                              {"tails", 1},
                              {"p", "0.021"}});
  EXPECT_TRUE(c.consistent) << c.recomputed;
}

TEST(PaperAudit, BadEntriesNameTheEntryAndKey) {
  std::string message = ErrorOf([] {
    Audit({{"kind", "grim"}, {"mean", 0.6457}, {"denominator", 420}});
  });
  EXPECT_NE(message.find("test.json: checks[0].mean"), std::string::npos) << message;
  EXPECT_NE(message.find("as a string"), std::string::npos) << message;
  message = ErrorOf([] { Audit({{"kind", "grim"}, {"mean", "0.5"}, {"denominatr", 420}}); });
  EXPECT_NE(message.find("checks[0].denominatr"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown key"), std::string::npos) << message;
  message = ErrorOf([] { Audit({{"kind", "statcheck"}}); });
  EXPECT_NE(message.find("checks[0].kind"), std::string::npos) << message;
  message = ErrorOf([] { Audit({{"kind", "grim"}, {"mean", "0.5e1"}, {"denominator", 4}}); });
  EXPECT_NE(message.find("no exponent"), std::string::npos) << message;
  message = ErrorOf([] {
    AuditPaper({{"checks", {{{"kind", "product"}, {"factors", {1}}, {"reported", 1}}}}}, "t.json");
  });
  EXPECT_NE(message.find("checks[0].id"), std::string::npos) << message;
}

TEST(PaperAudit, ReportedValueDecimals) {
  EXPECT_EQ(ParseReportedValue("26.88", "x").decimals, 2);
  EXPECT_EQ(ParseReportedValue("0.0001", "x").decimals, 4);
  EXPECT_EQ(ParseReportedValue("420", "x").decimals, 0);
  EXPECT_DOUBLE_EQ(ParseReportedValue("-1.5", "x").value, -1.5);
  EXPECT_DOUBLE_EQ(ParseReportedValue("0.133", "x").HalfWidth(), 0.0005);
}

}  // namespace
}  // namespace mmh::study
