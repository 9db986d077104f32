// Tests of core/text_parsing.h and the number formatting of core/error.h.
#include "core/text_parsing.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::vector<std::string> Fields(std::string_view line, std::string_view delimiters) {
  std::vector<std::string> out;
  for (auto f : SplitFields(line, delimiters)) out.emplace_back(f);
  return out;
}

bool Parses(std::string_view text, double* value = nullptr) {
  double v = -12345.0;
  const bool ok = ParseDouble(text, &v);
  if (value) *value = v;
  return ok;
}

TEST(TextParsing, ParseDoubleAcceptsPlainNumbers) {
  double v = 0;
  EXPECT_TRUE(Parses("1.5", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_TRUE(Parses("-0.25", &v));
  EXPECT_EQ(v, -0.25);
  EXPECT_TRUE(Parses("42", &v));
  EXPECT_EQ(v, 42.0);
  EXPECT_TRUE(Parses("1e-3", &v));
  EXPECT_EQ(v, 1e-3);
  EXPECT_TRUE(Parses("6.02E23", &v));
  EXPECT_EQ(v, 6.02e23);
  EXPECT_TRUE(Parses(".5", &v));
  EXPECT_EQ(v, 0.5);
  EXPECT_TRUE(Parses("5.", &v));
  EXPECT_EQ(v, 5.0);
  EXPECT_TRUE(Parses("1305031102.175304", &v));
  EXPECT_EQ(v, 1305031102.175304);
}

TEST(TextParsing, ParseDoubleAcceptsExplicitPlus) {
  double v = 0;
  EXPECT_TRUE(Parses("+1.5", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_TRUE(Parses("+0", &v));
  EXPECT_EQ(v, 0.0);
  EXPECT_TRUE(Parses("+2e+2", &v));
  EXPECT_EQ(v, 200.0);
}

TEST(TextParsing, ParseDoubleAcceptsSurroundingWhitespace) {
  double v = 0;
  EXPECT_TRUE(Parses(" 1.5 ", &v));
  EXPECT_EQ(v, 1.5);
  EXPECT_TRUE(Parses("\t-2\r", &v));
  EXPECT_EQ(v, -2.0);
}

TEST(TextParsing, ParseDoubleRejectsTrailingGarbage) {
  EXPECT_FALSE(Parses("1.5x"));
  EXPECT_FALSE(Parses("1.5 x"));
  EXPECT_FALSE(Parses("1.5.2"));
  EXPECT_FALSE(Parses("1,5"));
  EXPECT_FALSE(Parses("1e"));
  EXPECT_FALSE(Parses("2m"));
  EXPECT_FALSE(Parses("3 4"));
  EXPECT_FALSE(Parses("0x10"));
}

TEST(TextParsing, ParseDoubleRejectsNonNumbers) {
  EXPECT_FALSE(Parses(""));
  EXPECT_FALSE(Parses("   "));
  EXPECT_FALSE(Parses("abc"));
  EXPECT_FALSE(Parses("+"));
  EXPECT_FALSE(Parses("-"));
  EXPECT_FALSE(Parses("."));
  EXPECT_FALSE(Parses("++1"));
  EXPECT_FALSE(Parses("--1"));
  EXPECT_FALSE(Parses("e5"));
}

TEST(TextParsing, ParseDoubleRejectsDoubleSign) {
  // "+-1" is not a number; it must not read as -1.
  double v = 0;
  EXPECT_FALSE(Parses("+-1", &v)) << "parsed as " << v;
  EXPECT_FALSE(Parses("+ 1", &v)) << "parsed as " << v;
}

TEST(TextParsing, ParseDoubleOutOfRangeIsRejected) {
  EXPECT_FALSE(Parses("1e999"));
  EXPECT_FALSE(Parses("-1e999"));
}

TEST(TextParsing, ParseDoubleReadsSpecialValuesForCallersToReject) {
  // nan and inf parse (the readers then reject them as non-finite).
  double v = 0;
  if (Parses("nan", &v)) {
    EXPECT_TRUE(std::isnan(v));
  }
  if (Parses("inf", &v)) {
    EXPECT_TRUE(std::isinf(v));
  }
}

TEST(TextParsing, ParseDoubleRoundTripsFormatNumber) {
  std::mt19937_64 rng(123);
  std::uniform_int_distribution<std::uint64_t> bits;
  int checked = 0;
  while (checked < 20000) {
    const std::uint64_t b = bits(rng);
    double x;
    std::memcpy(&x, &b, sizeof x);
    if (!std::isfinite(x)) continue;
    ++checked;
    double y = 0;
    ASSERT_TRUE(ParseDouble(FormatNumber(x), &y)) << FormatNumber(x);
    ASSERT_EQ(std::memcmp(&x, &y, sizeof x), 0) << FormatNumber(x);
  }
  // Edge values.
  for (double x : {0.0, -0.0, std::numeric_limits<double>::min(),
                   std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
                   std::numeric_limits<double>::epsilon(), 0.1, 1.0 / 3.0}) {
    double y = 0;
    ASSERT_TRUE(ParseDouble(FormatNumber(x), &y)) << FormatNumber(x);
    EXPECT_EQ(std::memcmp(&x, &y, sizeof x), 0) << FormatNumber(x);
  }
}

TEST(TextParsing, ParseDoubleReadsSubnormals) {
  // FormatNumber writes subnormals such as 5e-324; they must read back.
  for (double x : {std::numeric_limits<double>::denorm_min(), 1e-310, -2.5e-320}) {
    double y = 0;
    EXPECT_TRUE(ParseDouble(FormatNumber(x), &y)) << FormatNumber(x);
    EXPECT_EQ(x, y) << FormatNumber(x);
  }
}

TEST(TextParsing, FormatNumberIsShortest) {
  EXPECT_EQ(FormatNumber(0.1), "0.1");
  EXPECT_EQ(FormatNumber(2.0), "2");
  EXPECT_EQ(FormatNumber(-0.5), "-0.5");
  EXPECT_EQ(FormatNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(FormatNumber(1e21), "1e+21");
  EXPECT_EQ(FormatNumber(std::nan("")), "nan");
  EXPECT_EQ(FormatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatNumber(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(TextParsing, DescribeBadValueShape) {
  EXPECT_EQ(DescribeBadValue("a.tum:3", "'x'", "a number"), "a.tum:3: got 'x', expected a number");
  try {
    ThrowBadValue("w", "v", "e");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "w: got v, expected e");
  }
}

TEST(TextParsing, SplitFieldsOnRunsOfDelimiters) {
  EXPECT_EQ(Fields("a b  c", " "), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(Fields("  a\t \tb  ", " \t"), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(Fields("1,2,3", ","), (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_EQ(Fields("x", " "), (std::vector<std::string>{"x"}));
  EXPECT_TRUE(Fields("", " ").empty());
  EXPECT_TRUE(Fields("    ", " ").empty());
  EXPECT_TRUE(Fields(",,,", ",").empty());
  // Empty fields are dropped.
  EXPECT_EQ(Fields("a,,b,", ","), (std::vector<std::string>{"a", "b"}));
  // Delimiters not listed stay inside fields.
  EXPECT_EQ(Fields("a\tb c", " "), (std::vector<std::string>{"a\tb", "c"}));
}

TEST(TextParsing, SplitFieldsReturnsViewsIntoTheLine) {
  const std::string line = "10 20";
  const auto fields = SplitFields(line, " ");
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_EQ(fields[0].data(), line.data());
  EXPECT_EQ(fields[1].data(), line.data() + 3);
}

TEST(TextParsing, Trim) {
  EXPECT_EQ(Trim("  a b \r\n"), "a b");
  EXPECT_EQ(Trim("\t\r\n "), "");
  EXPECT_EQ(Trim(""), "");
  EXPECT_EQ(Trim("x"), "x");
}

class TextFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = fs::temp_directory_path() /
           ("mmh_core_text_" + std::to_string(::getpid()) + "_" + std::to_string(rd()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(TextFileTest, ReadTextFileReadsBytesVerbatim) {
  const std::string bytes = std::string("a\r\nb\0c\n", 7);
  {
    std::ofstream out(dir_ / "f.txt", std::ios::binary);
    out << bytes;
  }
  EXPECT_EQ(ReadTextFile(dir_ / "f.txt"), bytes);
}

TEST_F(TextFileTest, ReadTextFileErrorsNameThePath) {
  try {
    ReadTextFile(dir_ / "missing.txt");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir_ / "missing.txt").string()));
    EXPECT_THAT(e.what(), HasSubstr("does not exist"));
  }
  try {
    ReadTextFile(dir_);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(dir_.string()));
    EXPECT_THAT(e.what(), HasSubstr("folder"));
  }
}

}  // namespace
}  // namespace mmh
