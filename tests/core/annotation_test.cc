// Tests of core/annotation.h: CSV round trip, header, range, timestamps, line endings.
#include "core/annotation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test_util::ReadBytes;
using test_util::ListDir;
using test_util::TempDir;
using test_util::WriteText;

std::string ReadCsvError(const fs::path& path) {
  try {
    ReadAnnotationCsv(path);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "ReadAnnotationCsv threw a non-InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "ReadAnnotationCsv did not throw for " << path;
  return "";
}

std::string ReadCsvErrorOf(const TempDir& dir, const std::string& text) {
  const fs::path path = dir / "bad.csv";
  WriteText(path, text);
  return ReadCsvError(path);
}

Annotation RandomAnnotation(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> value(-5.0, 5.0);
  Annotation annotation;
  for (std::size_t i = 0; i < n; ++i) {
    annotation.timestamps.push_back(static_cast<double>(i) / 30.0);
    annotation.values.push_back(value(rng));
  }
  return annotation;
}

TEST(Annotation, RoundTripIsBitExact) {
  TempDir dir;
  Annotation annotation = RandomAnnotation(300, 1);
  annotation.values[0] = -5.0;
  annotation.values[1] = 5.0;
  annotation.values[2] = 0.0;
  annotation.values[3] = 1e-300;
  annotation.values[4] = 0.1 + 0.2;
  const fs::path path = dir / "take_1.csv";
  WriteAnnotationCsv(path, annotation);
  const Annotation read = ReadAnnotationCsv(path);
  ASSERT_EQ(read.size(), annotation.size());
  ASSERT_EQ(read.timestamps.size(), annotation.timestamps.size());
  for (std::size_t i = 0; i < annotation.size(); ++i) {
    EXPECT_EQ(read.timestamps[i], annotation.timestamps[i]) << i;
    EXPECT_EQ(read.values[i], annotation.values[i]) << i;
  }
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"take_1.csv"});
}

TEST(Annotation, WritesHeaderAndShortestNumbers) {
  TempDir dir;
  Annotation annotation;
  annotation.timestamps = {0.0, 0.1, 2.0};
  annotation.values = {-5.0, 0.25, 5.0};
  const fs::path path = dir / "a.csv";
  WriteAnnotationCsv(path, annotation);
  EXPECT_EQ(ReadBytes(path), "timestamp,value\n0,-5\n0.1,0.25\n2,5\n");
  // Same annotation twice: same bytes.
  WriteAnnotationCsv(dir / "b.csv", annotation);
  EXPECT_EQ(ReadBytes(path), ReadBytes(dir / "b.csv"));
}

TEST(Annotation, CrlfLineEndingsAndBlankLinesAreAccepted) {
  TempDir dir;
  const fs::path path = dir / "crlf.csv";
  WriteText(path, "timestamp,value\r\n0,1.5\r\n\r\n0.5,-2\r\n1, 3 \r\n");
  const Annotation annotation = ReadAnnotationCsv(path);
  EXPECT_EQ(annotation.timestamps, (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(annotation.values, (std::vector<double>{1.5, -2.0, 3.0}));
}

TEST(Annotation, CrlfHeaderOnlyLastLineWithoutNewline) {
  TempDir dir;
  const fs::path path = dir / "crlf2.csv";
  WriteText(path, "timestamp,value\r\n0,0\r\n0.1,+1.5");
  const Annotation annotation = ReadAnnotationCsv(path);
  ASSERT_EQ(annotation.size(), 2u);
  EXPECT_EQ(annotation.values[1], 1.5);
}

TEST(Annotation, HeaderIsRequired) {
  TempDir dir;
  const std::string missing = ReadCsvErrorOf(dir, "0,1\n0.1,2\n");
  EXPECT_THAT(missing, HasSubstr((dir / "bad.csv").string() + ":1"));
  EXPECT_THAT(missing, HasSubstr("timestamp,value"));
  EXPECT_THAT(missing, HasSubstr("0,1"));

  const std::string wrong = ReadCsvErrorOf(dir, "time,value\n0,1\n");
  EXPECT_THAT(wrong, HasSubstr(":1"));
  EXPECT_THAT(wrong, HasSubstr("'time,value'"));

  const std::string swapped = ReadCsvErrorOf(dir, "value,timestamp\n0,1\n");
  EXPECT_THAT(swapped, HasSubstr("value,timestamp"));

  const std::string extra = ReadCsvErrorOf(dir, "timestamp,value,other\n0,1,2\n");
  EXPECT_THAT(extra, HasSubstr("timestamp,value,other"));
}

TEST(Annotation, ValuesOutsideRangeAreRejectedNamingLineAndValue) {
  TempDir dir;
  const std::string high = ReadCsvErrorOf(dir, "timestamp,value\n0,1\n0.1,5.5\n");
  EXPECT_THAT(high, HasSubstr((dir / "bad.csv").string() + ":3"));
  EXPECT_THAT(high, HasSubstr("5.5"));
  EXPECT_THAT(high, HasSubstr("[-5, 5]"));

  const std::string low = ReadCsvErrorOf(dir, "timestamp,value\n\n0,-5.000001\n");
  EXPECT_THAT(low, HasSubstr(":3"));
  EXPECT_THAT(low, HasSubstr("-5.000001"));

  const std::string nan = ReadCsvErrorOf(dir, "timestamp,value\n0,nan\n");
  EXPECT_THAT(nan, HasSubstr(":2"));
  EXPECT_THAT(nan, HasSubstr("nan"));

  const std::string inf = ReadCsvErrorOf(dir, "timestamp,value\n0,inf\n");
  EXPECT_THAT(inf, HasSubstr("inf"));
}

TEST(Annotation, RangeEndsAreAccepted) {
  TempDir dir;
  const fs::path path = dir / "ends.csv";
  WriteText(path, "timestamp,value\n0,-5\n1,5\n2,-5.0\n3,5.0e0\n");
  const Annotation annotation = ReadAnnotationCsv(path);
  EXPECT_EQ(annotation.values, (std::vector<double>{-5, 5, -5, 5}));
}

TEST(Annotation, NonNumericFieldsAreRejected) {
  TempDir dir;
  const std::string value = ReadCsvErrorOf(dir, "timestamp,value\n0,1\n0.1,high\n");
  EXPECT_THAT(value, HasSubstr(":3"));
  EXPECT_THAT(value, HasSubstr("'high'"));
  const std::string timestamp = ReadCsvErrorOf(dir, "timestamp,value\n0s,1\n");
  EXPECT_THAT(timestamp, HasSubstr(":2"));
  EXPECT_THAT(timestamp, HasSubstr("'0s'"));
  const std::string nan_time = ReadCsvErrorOf(dir, "timestamp,value\nnan,1\n");
  EXPECT_THAT(nan_time, HasSubstr("'nan'"));
}

TEST(Annotation, WrongFieldCountIsRejected) {
  TempDir dir;
  const std::string three = ReadCsvErrorOf(dir, "timestamp,value\n0,1,2\n");
  EXPECT_THAT(three, HasSubstr(":2"));
  EXPECT_THAT(three, HasSubstr("0,1,2"));
  const std::string one = ReadCsvErrorOf(dir, "timestamp,value\n0\n");
  EXPECT_THAT(one, HasSubstr(":2"));
}

TEST(Annotation, EmptyCsvFieldIsNotSilentlySkipped) {
  // "0.1,,0.5" has three fields, one of them empty: it must not read as timestamp 0.1, value 0.5.
  TempDir dir;
  const std::string message = ReadCsvErrorOf(dir, "timestamp,value\n0,1\n0.1,,0.5\n");
  EXPECT_THAT(message, HasSubstr(":3"));
  // A trailing comma makes a third, empty field.
  const std::string trailing = ReadCsvErrorOf(dir, "timestamp,value\n0,1,\n");
  EXPECT_THAT(trailing, HasSubstr(":2"));
  // A row with a missing timestamp is rejected.
  const std::string leading = ReadCsvErrorOf(dir, "timestamp,value\n,0.5\n");
  EXPECT_THAT(leading, HasSubstr(":2"));
}

TEST(Annotation, NonIncreasingTimestampsAreRejected) {
  TempDir dir;
  const std::string equal = ReadCsvErrorOf(dir, "timestamp,value\n0,1\n0.1,1\n0.1,2\n");
  EXPECT_THAT(equal, HasSubstr((dir / "bad.csv").string() + ":4"));
  EXPECT_THAT(equal, HasSubstr("0.1"));
  EXPECT_THAT(equal, HasSubstr("timestamp"));
  const std::string decreasing = ReadCsvErrorOf(dir, "timestamp,value\n1,1\n0.5,2\n");
  EXPECT_THAT(decreasing, HasSubstr(":3"));
  EXPECT_THAT(decreasing, HasSubstr("0.5"));
  EXPECT_THAT(decreasing, HasSubstr("previous timestamp 1"));
}

TEST(Annotation, EmptyAndHeaderOnlyFilesAreRejected) {
  TempDir dir;
  const std::string empty = ReadCsvErrorOf(dir, "");
  EXPECT_THAT(empty, HasSubstr((dir / "bad.csv").string()));
  EXPECT_THAT(empty, HasSubstr("empty"));
  const std::string blank = ReadCsvErrorOf(dir, "\n\r\n  \n");
  EXPECT_THAT(blank, HasSubstr((dir / "bad.csv").string()));
  const std::string header_only = ReadCsvErrorOf(dir, "timestamp,value\n");
  EXPECT_THAT(header_only, HasSubstr((dir / "bad.csv").string()));
  EXPECT_THAT(header_only, HasSubstr("no rows"));
  const std::string header_only_crlf = ReadCsvErrorOf(dir, "timestamp,value\r\n\r\n");
  EXPECT_THAT(header_only_crlf, HasSubstr("no rows"));
}

TEST(Annotation, MissingFileAndFolderAreRejected) {
  TempDir dir;
  const std::string missing = ReadCsvError(dir / "nope.csv");
  EXPECT_THAT(missing, HasSubstr((dir / "nope.csv").string()));
  fs::create_directory(dir / "folder.csv");
  const std::string folder = ReadCsvError(dir / "folder.csv");
  EXPECT_THAT(folder, HasSubstr((dir / "folder.csv").string()));
}

TEST(Annotation, ValidateAnnotationErrors) {
  Annotation ok = RandomAnnotation(5, 2);
  EXPECT_NO_THROW(ValidateAnnotation(ok, "take 1"));

  Annotation sizes = ok;
  sizes.timestamps.pop_back();
  try {
    ValidateAnnotation(sizes, "take 1");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("take 1"));
    EXPECT_THAT(e.what(), HasSubstr("4 timestamps for 5 values"));
  }

  Annotation range = ok;
  range.values[3] = 6.0;
  try {
    ValidateAnnotation(range, "take 2");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("take 2, frame 3"));
    EXPECT_THAT(e.what(), HasSubstr("6"));
  }

  Annotation order = ok;
  order.timestamps[2] = order.timestamps[1];
  try {
    ValidateAnnotation(order, "take 3");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("take 3, frame 2"));
  }
}

TEST(Annotation, WriteRejectsInvalidAnnotationAndKeepsOldFile) {
  TempDir dir;
  const fs::path path = dir / "keep.csv";
  WriteText(path, "old");
  Annotation bad = RandomAnnotation(4, 3);
  bad.values[1] = -7;
  EXPECT_THROW(WriteAnnotationCsv(path, bad), InputError);
  EXPECT_EQ(ReadBytes(path), "old");
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"keep.csv"});
}

TEST(Annotation, WritingIntoNonexistentFolderThrowsAndCreatesNothing) {
  TempDir dir;
  EXPECT_THROW(WriteAnnotationCsv(dir / "missing" / "a.csv", RandomAnnotation(3, 4)), InputError);
  EXPECT_TRUE(ListDir(dir.path()).empty());
}

TEST(Annotation, EmptyAnnotationIsNotWrittenAsAnUnreadableFile) {
  // WriteAnnotationCsv must not write a file ReadAnnotationCsv rejects.
  TempDir dir;
  const fs::path path = dir / "empty.csv";
  bool wrote = false;
  try {
    WriteAnnotationCsv(path, Annotation{});
    wrote = true;
  } catch (const InputError&) {
  }
  if (wrote) {
    EXPECT_NO_THROW(ReadAnnotationCsv(path))
        << "WriteAnnotationCsv accepted an empty annotation and wrote '" << ReadBytes(path)
        << "', which ReadAnnotationCsv rejects";
  }
}

}  // namespace
}  // namespace mmh
