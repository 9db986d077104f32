#include "study/study_data.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace mmh::study {
namespace {

using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;

const std::filesystem::path kExample =
    std::filesystem::path(MMH_SOURCE_DIR) / "examples" / "study_data";

// A valid two-animator study; tests break one thing at a time.
struct Files {
  std::string rankings =
      "animator,item,rank\n"
      "A,take1,2\nA,take2,3\nA,montage,1\n"
      "B,take1,3\nB,take2,1\nB,montage,2\n";
  std::string comparisons =
      "scorer,animator,take,montage_preferred\n"
      "S1,A,1,1\nS1,B,2,0\nS2,A,2,1\nS2,B,1,1\n";
  std::string segment_costs;

  void Write(const TempDir& dir) const {
    WriteText(dir / "rankings.csv", rankings);
    WriteText(dir / "comparisons.csv", comparisons);
    if (!segment_costs.empty()) WriteText(dir / "segment_costs.csv", segment_costs);
  }
};

std::string ErrorReading(const Files& files, const StudyDataOptions& options = {}) {
  TempDir dir;
  files.Write(dir);
  return ErrorOf([&] { ReadStudyData(dir.path(), options); });
}

void ExpectContains(const std::string& message, const std::vector<std::string>& parts) {
  for (const auto& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  }
}

TEST(StudyData, ReadsTheExample) {
  const StudyData data = ReadStudyData(kExample);
  EXPECT_EQ(data.rankings.size(), 80u);
  EXPECT_EQ(data.comparisons.size(), 420u);
  EXPECT_EQ(data.segment_costs.size(), 20u);
  EXPECT_EQ(data.rankings[3].item, "montage");
  EXPECT_EQ(data.rankings[3].line, 5);
}

TEST(StudyData, WriteThenReadGivesTheSameRows) {
  const StudyData data = ReadStudyData(kExample);
  TempDir dir;
  WriteStudyData(dir.path(), data);
  const StudyData again = ReadStudyData(dir.path());
  EXPECT_EQ(test_util::ReadBytes(dir / "comparisons.csv"), ComparisonsToCsv(data.comparisons));
  ASSERT_EQ(again.comparisons.size(), data.comparisons.size());
  for (std::size_t i = 0; i < data.comparisons.size(); ++i) {
    EXPECT_EQ(again.comparisons[i].scorer, data.comparisons[i].scorer);
    EXPECT_EQ(again.comparisons[i].take, data.comparisons[i].take);
    EXPECT_EQ(again.comparisons[i].montage_preferred, data.comparisons[i].montage_preferred);
  }
  ASSERT_EQ(again.segment_costs.size(), data.segment_costs.size());
  EXPECT_EQ(again.segment_costs[1].cost_constrained, data.segment_costs[1].cost_constrained);
}

TEST(StudyData, ColumnsInAnyOrderCommentsAndBlankLines) {
  Files f;
  f.comparisons =
      "# exported 2026-11-21\n"
      "montage_preferred,take,animator,scorer\n"
      "1,1,A,S1\n\n0,2,B,S1\r\n1,2,A,S2\n1,1,B,S2\n";
  TempDir dir;
  f.Write(dir);
  const StudyData data = ReadStudyData(dir.path());
  ASSERT_EQ(data.comparisons.size(), 4u);
  EXPECT_EQ(data.comparisons[1].animator, "B");
  EXPECT_FALSE(data.comparisons[1].montage_preferred);
  EXPECT_EQ(data.comparisons[1].line, 5);
}

TEST(StudyData, MissingOrUnknownColumnNamesFileLineAndExpectation) {
  Files f;
  f.rankings = "animator,item\nA,take1\n";
  ExpectContains(ErrorReading(f),
                 {"rankings.csv:1", "without the column 'rank'", "animator,item,rank"});
  f = Files();
  f.comparisons = "scorer,animator,take,montage_prefered\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv:1", "'montage_prefered'",
                                   "scorer,animator,take,montage_preferred"});
}

TEST(StudyData, WrongTypesNameLineColumnValueAndExpectation) {
  Files f;
  f.comparisons += "S3,A,1,yes\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv:6", "column 'montage_preferred'", "'yes'",
                                   "1 (the montage was preferred) or 0"});
  f = Files();
  f.comparisons += "S3,A,0,1\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv:6", "column 'take'", "'0'", "take number"});
  f = Files();
  f.rankings += "C,take1,first\n";
  ExpectContains(ErrorReading(f), {"rankings.csv:8", "column 'rank'", "'first'"});
  f = Files();
  f.rankings += "C,take_1,1\n";
  ExpectContains(ErrorReading(f), {"rankings.csv:8", "column 'item'", "'take_1'", "take<k>"});
  f = Files();
  f.comparisons += "S3,A,2\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv:6", "3 fields", "4 fields"});
  f = Files();
  f.comparisons += "S3,\"A\",2,1\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv:6", "quoted"});
}

TEST(StudyData, RanksMustBeAPermutation) {
  Files f;
  f.rankings = "animator,item,rank\nA,take1,1\nA,take2,1\nA,montage,3\n";
  ExpectContains(ErrorReading(f),
                 {"rankings.csv:2", "ranks 1, 1, 3", "animator 'A'", "a permutation of 1..3"});
  f.rankings = "animator,item,rank\nA,take1,1.5\nA,take2,1.5\nA,montage,3\n";
  ExpectContains(ErrorReading(f), {"permutation"});
  EXPECT_EQ(ErrorReading(f, StudyDataOptions{.allow_tied_ranks = true}), "(no InputError)");
  f.rankings = "animator,item,rank\nA,take1,1.5\nA,take2,2\nA,montage,3\n";
  ExpectContains(ErrorReading(f, StudyDataOptions{.allow_tied_ranks = true}), {"mid-ranks"});
}

TEST(StudyData, EveryAnimatorRanksTheSameItemsOnce) {
  Files f;
  f.rankings += "C,take1,1\nC,montage,2\n";
  ExpectContains(ErrorReading(f), {"rankings.csv:8", "animator 'C' ranking 2 items",
                                   "the 3 items every animator ranks (montage, take1, take2)"});
  f = Files();
  f.rankings += "A,take1,2\n";
  ExpectContains(ErrorReading(f), {"rankings.csv:8", "second rank of item 'take1'", "line 2"});
}

TEST(StudyData, ComparisonRules) {
  Files f;
  f.comparisons += "S1,A,1,0\n";
  ExpectContains(ErrorReading(f),
                 {"comparisons.csv:6", "second comparison by scorer 'S1'", "first on line 2"});
  f = Files();
  f.comparisons += "S3,A,4,1\n";
  ExpectContains(ErrorReading(f), {"never take 3", "takes numbered 1..K"});
  f = Files();
  f.comparisons = "scorer,animator,take,montage_preferred\n";
  ExpectContains(ErrorReading(f), {"comparisons.csv", "no rows"});
}

TEST(StudyData, SegmentCostRules) {
  Files f;
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained\nA,10,9.5,2\n";
  ExpectContains(ErrorReading(f),
                 {"segment_costs.csv:2", "column 'cost_constrained'", "9.5", "cannot lower"});
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained\nA,10,nan,2\n";
  ExpectContains(ErrorReading(f), {"segment_costs.csv:2", "'nan'"});
}

TEST(StudyData, NegativeCostsAreAccepted) {
  // The compositor's data cost is -a'(t): C_T is negative where the takes are liked.
  Files f;
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained\n"
      "A,-200,-199,2\nB,-50.5,3,0\n";
  TempDir dir;
  f.Write(dir);
  const StudyData data = ReadStudyData(dir.path());
  ASSERT_EQ(data.segment_costs.size(), 2u);
  EXPECT_EQ(data.segment_costs[0].cost_unconstrained, -200.0);
  EXPECT_EQ(data.segment_costs[1].cost_constrained, 3.0);
  // Still: the constraint cannot lower the optimum.
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained\nA,-10,-11,2\n";
  ExpectContains(ErrorReading(f), {"segment_costs.csv:2", "column 'cost_constrained'", "-11"});
}

TEST(StudyData, MissingFilesAndFolders) {
  TempDir dir;
  ExpectContains(ErrorOf([&] { ReadStudyData(dir / "nope"); }), {"nope", "not a folder"});
  WriteText(dir / "comparisons.csv", Files().comparisons);
  ExpectContains(ErrorOf([&] { ReadStudyData(dir.path()); }), {"rankings.csv", "does not exist"});
  WriteText(dir / "rankings.csv", "");
  ExpectContains(ErrorOf([&] { ReadStudyData(dir.path()); }), {"rankings.csv", "empty file"});
}

TEST(StudyData, WriterRefusesIdsThatWouldBreakTheCsv) {
  StudyData data;
  data.rankings = {{"A,1", "take1", 1.0}, {"A,1", "montage", 2.0}};
  data.comparisons = {{"S", "A", 1, true}};
  TempDir dir;
  ExpectContains(ErrorOf([&] { WriteStudyData(dir.path(), data); }), {"'A,1'", "without commas"});
  EXPECT_FALSE(std::filesystem::exists(dir / "rankings.csv"));
}

TEST(StudyData, TakeNumberOfItem) {
  EXPECT_EQ(TakeNumberOfItem("take1"), 1);
  EXPECT_EQ(TakeNumberOfItem("take12"), 12);
  EXPECT_EQ(TakeNumberOfItem("take0"), 0);
  EXPECT_EQ(TakeNumberOfItem("take01"), 0);
  EXPECT_EQ(TakeNumberOfItem("take"), 0);
  EXPECT_EQ(TakeNumberOfItem("montage"), 0);
}

}  // namespace
}  // namespace mmh::study

namespace mmh::study {
namespace {

TEST(StudyData, ReferenceFramesColumnIsOptional) {
  Files f;
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained,reference_frames\n"
      "A,-200,-199,2,1500\n";
  TempDir dir;
  f.Write(dir);
  const StudyData data = ReadStudyData(dir.path());
  ASSERT_EQ(data.segment_costs.size(), 1u);
  EXPECT_EQ(data.segment_costs[0].reference_frames, 1500);
  // Written back only when every row has it.
  EXPECT_NE(SegmentCostsToCsv(data.segment_costs).find(",reference_frames\nA,-200,-199,2,1500\n"),
            std::string::npos);
  StudyData without = data;
  without.segment_costs[0].reference_frames = 0;
  EXPECT_EQ(SegmentCostsToCsv(without.segment_costs).find("reference_frames"), std::string::npos);
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained,reference_frames\n"
      "A,-200,-199,2,0\n";
  ExpectContains(ErrorReading(f), {"segment_costs.csv:2", "column 'reference_frames'", "0"});
  f.segment_costs =
      "animator,cost_unconstrained,cost_constrained,short_segments_unconstrained,frames\n"
      "A,-200,-199,2,10\n";
  ExpectContains(ErrorReading(f), {"segment_costs.csv:1", "frames"});
}

}  // namespace
}  // namespace mmh::study
