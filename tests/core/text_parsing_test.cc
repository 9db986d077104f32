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
  const std::string bytes = std::string("a\r\nb\tc \xC2\xB1\n");
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

// A binary file (a .glb) is read whole, NUL bytes and all, with the same bound and path errors.
TEST_F(TextFileTest, ReadBinaryFileReadsEveryByteAndKeepsTheBound) {
  std::string bytes = "glTF";
  bytes += std::string("\0\x02\0\0", 4);
  bytes += std::string(70000, '\xFF');  // more than one read chunk
  {
    std::ofstream out(dir_ / "f.glb", std::ios::binary);
    out << bytes;
  }
  EXPECT_EQ(ReadBinaryFile(dir_ / "f.glb"), bytes);
  EXPECT_THROW(ReadTextFile(dir_ / "f.glb"), InputError);
  try {
    ReadBinaryFile(dir_ / "f.glb", 1000);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir_ / "f.glb").string()));
    EXPECT_THAT(e.what(), HasSubstr("more than"));
  }
  EXPECT_THROW(ReadBinaryFile(dir_ / "missing.glb"), InputError);
}

std::string ErrorReading(const fs::path& path, std::size_t max_bytes = kMaxTextFileBytes) {
  try {
    ReadTextFile(path, max_bytes);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST_F(TextFileTest, ReadTextFileDropsAUtf8ByteOrderMark) {
  std::ofstream(dir_ / "bom.csv", std::ios::binary) << "\xEF\xBB\xBFtimestamp,value\n";
  EXPECT_EQ(ReadTextFile(dir_ / "bom.csv"), "timestamp,value\n");
}

TEST_F(TextFileTest, ReadTextFileNamesUtf16AndBinaryFiles) {
  // UTF-16 with and without a byte-order mark, UTF-32, binary: each named, never cut at a NUL.
  const std::pair<std::string, std::string> cases[] = {
      {std::string("\xFF\xFEt\0i\0m\0e\0", 10), "a UTF-16 file (byte-order mark)"},
      {std::string("\xFE\xFF\0t\0i\0m\0e", 10), "a UTF-16 file (byte-order mark)"},
      {std::string("t\0i\0m\0e\0s\0", 10), "a UTF-16 file (NUL bytes between"},
      {std::string("\xFF\xFE\0\0t\0\0\0", 8), "a UTF-32 file"},
      {std::string("PK\x03\x04\0\0\0\0garbage", 15), "binary data (a NUL byte at offset 4)"},
  };
  for (const auto& [bytes, named] : cases) {
    std::ofstream(dir_ / "f.bin", std::ios::binary) << bytes;
    const std::string message = ErrorReading(dir_ / "f.bin");
    EXPECT_THAT(message, HasSubstr((dir_ / "f.bin").string())) << named;
    EXPECT_THAT(message, HasSubstr(named));
    EXPECT_THAT(message, HasSubstr("expected a UTF-8 text file"));
  }
}

TEST_F(TextFileTest, ReadTextFileRefusesEndlessAndHugeInputs) {
  // /dev/zero never ends: refused at its first chunk (NUL bytes), not by running out of memory.
  EXPECT_THAT(ErrorReading("/dev/zero"), HasSubstr("/dev/zero: got binary data"));
  std::ofstream(dir_ / "big.txt", std::ios::binary) << std::string(5000, 'x');
  const std::string message = ErrorReading(dir_ / "big.txt", 4096);
  EXPECT_THAT(message, HasSubstr("got more than 4096 bytes"));
  EXPECT_THAT(message, HasSubstr("of at most 4096 bytes"));
  EXPECT_EQ(ReadTextFile(dir_ / "big.txt", 5000).size(), 5000u);
}

TEST_F(TextFileTest, ForEachDataRowQuotesALongLineShortly) {
  // A 2 MB line is quoted as a few dozen characters with its length, escaped.
  std::ofstream(dir_ / "long.tum", std::ios::binary)
      << "1 2 \x01" << std::string(2'000'000, 'y') << "\n";
  try {
    ForEachDataRow(dir_ / "long.tum", 8, "8 fields", [](auto&&...) {});
    ADD_FAILURE();
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_LT(message.size(), 300u) << message.substr(0, 400);
    EXPECT_THAT(message, HasSubstr("long.tum:1: got 3 fields ('1 2 \\x01yyy"));
    EXPECT_THAT(message, HasSubstr("(2000005 bytes in all)"));
  }
}

}  // namespace
}  // namespace mmh
