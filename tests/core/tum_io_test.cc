// Tests of core/tum_io.h: bit-exact round trip, comments, validation errors, atomic writing.
#include "core/tum_io.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/resource_limits.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test_util::ReadBytes;
using test_util::ListDir;
using test_util::TempDir;
using test_util::WriteText;

// Runs ReadTum expecting an InputError; returns its message.
std::string ReadTumError(const fs::path& path) {
  try {
    ReadTum(path);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "ReadTum threw a non-InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "ReadTum did not throw for " << path;
  return "";
}

std::string ReadTumErrorOf(const TempDir& dir, const std::string& text) {
  const fs::path path = dir / "bad.tum";
  WriteText(path, text);
  return ReadTumError(path);
}

Trajectory RandomTrajectory(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> dt(0.001, 0.1);
  Trajectory trajectory;
  double t = 1305031102.175304;  // a TUM-style epoch timestamp
  for (std::size_t i = 0; i < n; ++i) {
    t += dt(rng);
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    q.normalize();
    trajectory.timestamps.push_back(t);
    trajectory.poses.emplace_back(
        q, Eigen::Vector3d(normal(rng), 1e-7 * normal(rng), 1e5 * normal(rng)));
  }
  return trajectory;
}

// Compares every number bit for bit; reports how many frames differ and the first few.
void ExpectBitIdentical(const Trajectory& wrote, const Trajectory& read) {
  ASSERT_EQ(wrote.size(), read.size());
  ASSERT_EQ(wrote.timestamps.size(), read.timestamps.size());
  std::size_t differing_frames = 0;
  std::ostringstream first;
  for (std::size_t i = 0; i < wrote.size(); ++i) {
    std::ostringstream frame;
    const auto check = [&](const char* name, double a, double b) {
      if (std::memcmp(&a, &b, sizeof a) != 0) {
        frame << " " << name << " wrote " << FormatNumber(a) << " read " << FormatNumber(b) << ";";
      }
    };
    check("timestamp", wrote.timestamps[i], read.timestamps[i]);
    check("tx", wrote.poses[i].translation.x(), read.poses[i].translation.x());
    check("ty", wrote.poses[i].translation.y(), read.poses[i].translation.y());
    check("tz", wrote.poses[i].translation.z(), read.poses[i].translation.z());
    check("qx", wrote.poses[i].rotation.x(), read.poses[i].rotation.x());
    check("qy", wrote.poses[i].rotation.y(), read.poses[i].rotation.y());
    check("qz", wrote.poses[i].rotation.z(), read.poses[i].rotation.z());
    check("qw", wrote.poses[i].rotation.w(), read.poses[i].rotation.w());
    if (!frame.str().empty()) {
      if (differing_frames < 3) first << "\n  frame " << i << ":" << frame.str();
      ++differing_frames;
    }
  }
  EXPECT_EQ(differing_frames, 0u) << differing_frames << " of " << wrote.size()
                                  << " frames differ after the round trip; first:" << first.str();
}

// ----------------------------------------------------------------------------------------------
// Round trip

TEST(TumIo, RoundTripSimpleValuesIsExact) {
  TempDir dir;
  Trajectory trajectory;
  trajectory.timestamps = {0.0, 0.1, 0.2};
  trajectory.poses = {
      Rigid3::Identity(), Rigid3(Eigen::Quaterniond(0, 1, 0, 0), Eigen::Vector3d(0.1, -0.2, 0.3)),
      Rigid3(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5), Eigen::Vector3d(1e-300, -0.0, 3))};
  const fs::path path = dir / "a.tum";
  WriteTum(path, trajectory);
  ExpectBitIdentical(trajectory, ReadTum(path));
}

TEST(TumIo, RoundTripOfRandomTrajectoryIsBitExact) {
  // Quaternions normalised once in double precision (as every producer does): reading back must
  // give the same bits for every number, including the quaternion.
  TempDir dir;
  const Trajectory trajectory = RandomTrajectory(500, 99);
  const fs::path path = dir / "random.tum";
  WriteTum(path, trajectory);
  ExpectBitIdentical(trajectory, ReadTum(path));
}

TEST(TumIo, RoundTripTimestampsAndTranslationsAreBitExact) {
  // The part of the round trip that involves no quaternion normalisation.
  TempDir dir;
  Trajectory trajectory = RandomTrajectory(500, 5);
  for (auto& pose : trajectory.poses) pose.rotation = Eigen::Quaterniond::Identity();
  trajectory.timestamps[0] = 0.1 + 0.2;  // 0.30000000000000004
  // The extremes a reader accepts: the largest coordinate below kMaxTranslationMetres (every bit
  // of the mantissa set), the smallest normal and the smallest subnormal.
  trajectory.poses[1].translation =
      Eigen::Vector3d(std::nextafter(kMaxTranslationMetres, 0.0),
                      std::numeric_limits<double>::min(), std::numeric_limits<double>::denorm_min());
  const fs::path path = dir / "t.tum";
  WriteTum(path, trajectory);
  ExpectBitIdentical(trajectory, ReadTum(path));
}

TEST(TumIo, WritesShortestRoundTripNumbers) {
  TempDir dir;
  Trajectory trajectory;
  trajectory.timestamps = {0.1, 2.0};
  trajectory.poses = {Rigid3(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(0.1, 0.25, -3)),
                      Rigid3(Eigen::Quaterniond(0, 0, 0, 1), Eigen::Vector3d(1e-9, 0, 1e6))};
  const fs::path path = dir / "short.tum";
  WriteTum(path, trajectory, "first line\nsecond line");
  const std::string text = ReadBytes(path);
  EXPECT_EQ(text,
            "# first line\n"
            "# second line\n"
            "0.1 0.1 0.25 -3 0 0 0 1\n"
            "2 1e-09 0 1e+06 0 0 1 0\n");
  // The comment lines are skipped when reading.
  ExpectBitIdentical(trajectory, ReadTum(path));
}

TEST(TumIo, SameTrajectoryTwiceGivesIdenticalBytes) {
  TempDir dir;
  const Trajectory trajectory = RandomTrajectory(100, 3);
  WriteTum(dir / "a.tum", trajectory, "take 1");
  WriteTum(dir / "b.tum", trajectory, "take 1");
  const std::string a = ReadBytes(dir / "a.tum");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, ReadBytes(dir / "b.tum"));
  // Overwriting the same file with the same trajectory gives the same bytes too.
  WriteTum(dir / "a.tum", trajectory, "take 1");
  EXPECT_EQ(a, ReadBytes(dir / "a.tum"));
}

TEST(TumIo, ReadWriteReadWriteIsAFixedPoint) {
  TempDir dir;
  const Trajectory trajectory = RandomTrajectory(100, 8);
  WriteTum(dir / "1.tum", trajectory);
  const Trajectory once = ReadTum(dir / "1.tum");
  WriteTum(dir / "2.tum", once);
  // Compare line by line so that a failure lists only the lines that changed.
  std::istringstream first(ReadBytes(dir / "1.tum")), second(ReadBytes(dir / "2.tum"));
  std::string a, b, report;
  std::size_t lines = 0, changed = 0;
  while (std::getline(first, a)) {
    ++lines;
    ASSERT_TRUE(std::getline(second, b)) << "second file is shorter";
    if (a != b) {
      if (++changed <= 2) report += "\n  wrote " + a + "\n  then  " + b;
    }
  }
  EXPECT_FALSE(std::getline(second, b)) << "second file is longer";
  EXPECT_EQ(changed, 0u) << changed << " of " << lines
                         << " lines changed when a read file is written again:" << report;
}

TEST(TumIo, NoTemporaryFilesLeftAfterWrite) {
  TempDir dir;
  const Trajectory trajectory = RandomTrajectory(10, 1);
  WriteTum(dir / "out.tum", trajectory);
  WriteTum(dir / "out.tum", trajectory);  // overwrite
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"out.tum"});
}

TEST(TumIo, WritingIntoNonexistentFolderThrowsAndCreatesNothing) {
  TempDir dir;
  const fs::path target = dir / "missing" / "sub" / "out.tum";
  const Trajectory trajectory = RandomTrajectory(3, 2);
  try {
    WriteTum(target, trajectory);
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(target.string()));
  }
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_TRUE(ListDir(dir.path()).empty());
}

TEST(TumIo, WriteRejectsInvalidTrajectoryAndKeepsOldFile) {
  TempDir dir;
  const fs::path path = dir / "keep.tum";
  WriteText(path, "old\n");
  Trajectory bad = RandomTrajectory(3, 4);
  bad.timestamps[2] = bad.timestamps[1];
  EXPECT_THROW(WriteTum(path, bad), InputError);
  EXPECT_EQ(ReadBytes(path), "old\n");
  EXPECT_EQ(ListDir(dir.path()), std::vector<std::string>{"keep.tum"});
}

TEST(TumIo, EmptyTrajectoryIsNotWrittenAsAnUnreadableFile) {
  // WriteTum must not produce a file that ReadTum then rejects: either it refuses the empty
  // trajectory, or the file it writes reads back.
  TempDir dir;
  const fs::path path = dir / "empty.tum";
  bool wrote = false;
  try {
    WriteTum(path, Trajectory{});
    wrote = true;
  } catch (const InputError&) {
  }
  if (wrote) {
    EXPECT_NO_THROW(ReadTum(path)) << "WriteTum accepted an empty trajectory and wrote a file ("
                                   << ReadBytes(path).size() << " bytes) that ReadTum rejects";
  }
}

// ----------------------------------------------------------------------------------------------
// Reading: accepted variations

TEST(TumIo, CommentsBlankLinesTabsAndCrlfAreAccepted) {
  TempDir dir;
  const fs::path path = dir / "c.tum";
  WriteText(path,
            "# timestamp tx ty tz qx qy qz qw\n"
            "\n"
            "   \n"
            "1.0 0 0 0 0 0 0 1\n"
            "  # indented comment\n"
            "1.5\t0.5\t-0.5  2   0 0 0 1\r\n"
            "\t\n"
            "2.0 1 2 3 0 0 1 0\n"
            "# trailing comment");
  const Trajectory trajectory = ReadTum(path);
  ASSERT_EQ(trajectory.size(), 3u);
  EXPECT_EQ(trajectory.timestamps, (std::vector<double>{1.0, 1.5, 2.0}));
  EXPECT_EQ(trajectory.poses[1].translation, Eigen::Vector3d(0.5, -0.5, 2.0));
  EXPECT_EQ(trajectory.poses[2].rotation.coeffs(), Eigen::Vector4d(0, 0, 1, 0));  // x y z w
  EXPECT_EQ(trajectory.poses[0].rotation.w(), 1.0);
}

TEST(TumIo, QuaternionOrderIsWLast) {
  TempDir dir;
  const fs::path path = dir / "q.tum";
  WriteText(path, "0 0 0 0 0.5 0.5 0.5 -0.5\n");
  const Trajectory trajectory = ReadTum(path);
  ASSERT_EQ(trajectory.size(), 1u);
  const auto& q = trajectory.poses[0].rotation;
  EXPECT_EQ(q.x(), 0.5);
  EXPECT_EQ(q.y(), 0.5);
  EXPECT_EQ(q.z(), 0.5);
  EXPECT_EQ(q.w(), -0.5);
}

TEST(TumIo, SlightlyNonUnitQuaternionsAreNormalised) {
  TempDir dir;
  const fs::path path = dir / "n.tum";
  // Norms 1.009 and 0.991 (inside 1 +- 0.01), and a 4-digit quaternion.
  WriteText(path,
            "0 0 0 0 0 0 0 1.009\n"
            "1 0 0 0 0 0.991 0 0\n"
            "2 0 0 0 0.1826 0.3651 0.5477 0.7303\n");
  const Trajectory trajectory = ReadTum(path);
  ASSERT_EQ(trajectory.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(trajectory.poses[i].rotation.norm(), 1.0, 1e-15) << i;
  }
  EXPECT_NEAR(trajectory.poses[0].rotation.w(), 1.0, 1e-15);
  EXPECT_NEAR(trajectory.poses[1].rotation.y(), 1.0, 1e-15);
  const Eigen::Vector4d raw(0.1826, 0.3651, 0.5477, 0.7303);
  const Eigen::Vector4d expected = raw / raw.norm();
  EXPECT_LT((trajectory.poses[2].rotation.coeffs() - expected).norm(), 1e-15);
  // A normalised trajectory passes the validation every algorithm runs.
  EXPECT_NO_THROW(ValidateTrajectory(trajectory, path.string()));
}

TEST(TumIo, ExplicitPlusSignAndExponentsAreAccepted) {
  TempDir dir;
  const fs::path path = dir / "e.tum";
  WriteText(path, "+1.5e0 -1E-3 +2 3e+0 0 0 0 1\n");
  const Trajectory trajectory = ReadTum(path);
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_EQ(trajectory.timestamps[0], 1.5);
  EXPECT_EQ(trajectory.poses[0].translation, Eigen::Vector3d(-1e-3, 2, 3));
}

// ----------------------------------------------------------------------------------------------
// Reading: errors name the file, the line and the value

TEST(TumIo, WrongFieldCountNamesFileLineAndContent) {
  TempDir dir;
  const std::string message = ReadTumErrorOf(dir,
                                             "# header\n"
                                             "0 0 0 0 0 0 0 1\n"
                                             "0.1 0 0 0 0 0 1\n");
  EXPECT_THAT(message, HasSubstr((dir / "bad.tum").string() + ":3"));
  EXPECT_THAT(message, HasSubstr("7 fields"));
  EXPECT_THAT(message, HasSubstr("0.1 0 0 0 0 0 1"));
  EXPECT_THAT(message, HasSubstr("8 fields"));

  const std::string too_many = ReadTumErrorOf(dir, "0 0 0 0 0 0 0 1 9\n");
  EXPECT_THAT(too_many, HasSubstr((dir / "bad.tum").string() + ":1"));
  EXPECT_THAT(too_many, HasSubstr("9 fields"));
}

TEST(TumIo, NonNumericFieldNamesFileLineFieldAndValue) {
  TempDir dir;
  const std::string message = ReadTumErrorOf(dir,
                                             "0 0 0 0 0 0 0 1\n"
                                             "\n"
                                             "0.1 0 abc 0 0 0 0 1\n");
  EXPECT_THAT(message, HasSubstr((dir / "bad.tum").string() + ":3"));
  EXPECT_THAT(message, HasSubstr("'abc'"));
  EXPECT_THAT(message, HasSubstr("ty"));
  EXPECT_THAT(message, HasSubstr("expected"));
}

TEST(TumIo, TrailingGarbageInANumberIsRejected) {
  TempDir dir;
  const std::string message = ReadTumErrorOf(dir, "0 0 0 0.5m 0 0 0 1\n");
  EXPECT_THAT(message, HasSubstr(":1"));
  EXPECT_THAT(message, HasSubstr("'0.5m'"));
  const std::string comma = ReadTumErrorOf(dir, "0,0 0 0 0 0 0 0 1\n");
  EXPECT_THAT(comma, HasSubstr("'0,0'"));
}

TEST(TumIo, NanAndInfAreRejected) {
  TempDir dir;
  for (const std::string bad : {"nan", "NaN", "inf", "-inf", "infinity", "1e999"}) {
    const std::string message = ReadTumErrorOf(dir, "0 0 0 0 0 0 0 1\n1 " + bad + " 0 0 0 0 0 1\n");
    EXPECT_THAT(message, HasSubstr((dir / "bad.tum").string() + ":2")) << bad;
    EXPECT_THAT(message, HasSubstr("'" + bad + "'")) << bad;
    EXPECT_THAT(message, HasSubstr("finite")) << bad;
  }
  // In the timestamp and in the quaternion too.
  EXPECT_THAT(ReadTumErrorOf(dir, "nan 0 0 0 0 0 0 1\n"), HasSubstr("'nan'"));
  EXPECT_THAT(ReadTumErrorOf(dir, "0 0 0 0 0 0 0 inf\n"), HasSubstr("'inf'"));
}

TEST(TumIo, ZeroQuaternionIsRejected) {
  TempDir dir;
  const std::string message = ReadTumErrorOf(dir,
                                             "0 0 0 0 0 0 0 1\n"
                                             "1 0 0 0 0 0 0 0\n");
  EXPECT_THAT(message, HasSubstr((dir / "bad.tum").string() + ":2"));
  EXPECT_THAT(message, HasSubstr("zero quaternion"));
  EXPECT_THAT(message, HasSubstr("unit quaternion"));
}

TEST(TumIo, QuaternionFarFromUnitIsRejected) {
  TempDir dir;
  const std::string message = ReadTumErrorOf(dir,
                                             "0 0 0 0 0 0 0 1\n"
                                             "1 0 0 0 0 0 0 2\n");
  EXPECT_THAT(message, HasSubstr((dir / "bad.tum").string() + ":2"));
  EXPECT_THAT(message, HasSubstr("norm"));
  EXPECT_THAT(message, HasSubstr("got 2"));
  // Just outside the tolerance on both sides.
  EXPECT_THAT(ReadTumErrorOf(dir, "0 0 0 0 0 0 0 1.02\n"), HasSubstr("1.02"));
  EXPECT_THAT(ReadTumErrorOf(dir, "0 0 0 0 0.98 0 0 0\n"), HasSubstr("0.98"));
  // A tiny but non-zero quaternion: far from unit.
  EXPECT_THAT(ReadTumErrorOf(dir, "0 0 0 0 0 0 0 1e-3\n"), HasSubstr(":1"));
}

TEST(TumIo, NonIncreasingTimestampsAreRejected) {
  TempDir dir;
  const std::string equal = ReadTumErrorOf(dir,
                                           "0.5 0 0 0 0 0 0 1\n"
                                           "# comment\n"
                                           "0.5 0 0 0 0 0 0 1\n");
  EXPECT_THAT(equal, HasSubstr((dir / "bad.tum").string() + ":3"));
  EXPECT_THAT(equal, HasSubstr("0.5"));
  EXPECT_THAT(equal, HasSubstr("timestamp"));

  const std::string decreasing = ReadTumErrorOf(dir,
                                                "1 0 0 0 0 0 0 1\n"
                                                "2 0 0 0 0 0 0 1\n"
                                                "1.25 0 0 0 0 0 0 1\n");
  EXPECT_THAT(decreasing, HasSubstr((dir / "bad.tum").string() + ":3"));
  EXPECT_THAT(decreasing, HasSubstr("1.25"));
  EXPECT_THAT(decreasing, HasSubstr("previous timestamp 2"));
}

TEST(TumIo, EmptyFileIsRejected) {
  TempDir dir;
  EXPECT_THAT(ReadTumErrorOf(dir, ""), HasSubstr((dir / "bad.tum").string()));
  EXPECT_THAT(ReadTumErrorOf(dir, "# only a comment\n\n  \n"),
              HasSubstr((dir / "bad.tum").string()));
}

TEST(TumIo, NonexistentPathIsRejected) {
  TempDir dir;
  const fs::path path = dir / "does_not_exist.tum";
  const std::string message = ReadTumError(path);
  EXPECT_THAT(message, HasSubstr(path.string()));
  EXPECT_THAT(message, HasSubstr("does not exist"));
}

// Coordinates beyond kMaxTranslationMetres (they overflowed the montage's costs) are refused
// where they are read, naming the line and field; the limit itself is accepted.
TEST(TumIo, TranslationsBeyondTheMeaningfulRangeAreRejected) {
  TempDir dir;
  for (const char* value : {"1e150", "1e200", "1e300", "-1000000.0001"}) {
    std::ofstream(dir / "huge.tum") << "0 0 0 0 0 0 0 1\n0.1 0 " << value << " 0 0 0 0 1\n";
    const std::string message = test_util::ErrorOf([&] { ReadTum(dir / "huge.tum"); });
    EXPECT_THAT(message, HasSubstr("huge.tum:2, field ty: got '" + std::string(value) + "'"));
    EXPECT_THAT(message, HasSubstr("expected a translation within +-1e6 m"));
  }
  std::ofstream(dir / "edge.tum") << "0 1e6 -1e6 1e6 0 0 0 1\n";
  EXPECT_EQ(ReadTum(dir / "edge.tum").poses[0].translation.x(), 1e6);
}

TEST(TumIo, DirectoryInsteadOfFileIsRejected) {
  TempDir dir;
  fs::create_directory(dir / "folder.tum");
  const std::string message = ReadTumError(dir / "folder.tum");
  EXPECT_THAT(message, HasSubstr((dir / "folder.tum").string()));
  EXPECT_THAT(message, HasSubstr("folder"));
}

}  // namespace
}  // namespace mmh
