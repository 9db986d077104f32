// Stories: the shipped ones load, and every kind of bad story gives an error that names the file
// and the beat.
#include "people/story.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

using test_util::ErrorOf;

std::string Repo(const std::string& relative) {
  return std::string(MMH_SOURCE_DIR) + "/" + relative;
}

TEST(StoryTest, ShippedStoriesLoad) {
  const Story soldier = LoadStory(Repo("configs/stories/soldier.json"));
  ASSERT_EQ(soldier.objects.size(), 1u);
  const StoryObject& o = soldier.objects[0];
  EXPECT_EQ(o.beats.size(), 20u);
  EXPECT_DOUBLE_EQ(o.end, 68.0);
  // The paper's beats are all there, in order.
  std::vector<BeatKind> kinds;
  for (const Beat& b : o.beats) kinds.push_back(b.kind);
  const auto position = [&](BeatKind k) {
    return std::find(kinds.begin(), kinds.end(), k) - kinds.begin();
  };
  EXPECT_LT(position(BeatKind::kMarch), position(BeatKind::kLookAround));
  EXPECT_LT(position(BeatKind::kLookAround), position(BeatKind::kStroll));
  EXPECT_LT(position(BeatKind::kStroll), position(BeatKind::kJump));
  EXPECT_LT(position(BeatKind::kJump), position(BeatKind::kSlip));
  EXPECT_LT(position(BeatKind::kSlip), position(BeatKind::kFall));
  EXPECT_LT(position(BeatKind::kFall), position(BeatKind::kGetUp));
  EXPECT_LT(position(BeatKind::kGetUp), position(BeatKind::kLimp));
  EXPECT_EQ(kinds.back(), BeatKind::kStand);

  const Story mario = LoadStory(Repo("configs/stories/mario.json"));
  // A round clockwise (seen from above, z up: the angle decreases), then anticlockwise.
  const std::vector<Eigen::Vector2d> first = mario.objects[0].BeatPolyline(0);
  const std::vector<Eigen::Vector2d> back = mario.objects[0].BeatPolyline(2);
  const auto turning = [](const std::vector<Eigen::Vector2d>& p) {
    double area = 0;  // shoelace: negative for clockwise
    for (std::size_t k = 0; k + 1 < p.size(); ++k)
      area += p[k].x() * p[k + 1].y() - p[k + 1].x() * p[k].y();
    return area;
  };
  EXPECT_LT(turning(first), 0);
  EXPECT_GT(turning(back), 0);
  EXPECT_NEAR((first.front() - first.back()).norm(), 0, 1e-9);

  const Story layered = LoadStory(Repo("configs/stories/mario_monster.json"));
  ASSERT_EQ(layered.objects.size(), 2u);
  EXPECT_EQ(layered.objects[1].beats[1].kind, BeatKind::kHit);
  EXPECT_EQ(layered.objects[1].beats[1].target, "monster");
}

TEST(StoryTest, PolylineGeometry) {
  const std::vector<Eigen::Vector2d> p = {{0, 0}, {1, 0}, {1, 2}};
  EXPECT_DOUBLE_EQ(PolylineLength(p), 3.0);
  Eigen::Vector2d tangent;
  EXPECT_TRUE(PolylinePoint(p, 2.0, &tangent).isApprox(Eigen::Vector2d(1, 1)));
  EXPECT_TRUE(tangent.isApprox(Eigen::Vector2d(0, 1)));
  EXPECT_TRUE(PolylinePoint(p, 10.0).isApprox(Eigen::Vector2d(1, 2)));
  EXPECT_DOUBLE_EQ(DistanceToPolyline(p, Eigen::Vector2d(0.5, 0.25)), 0.25);
  EXPECT_DOUBLE_EQ(DistanceToPolyline(p, Eigen::Vector2d(2, 1)), 1.0);
}

std::string StoryWith(const std::string& beats, const std::string& path = "[[0, 0], [0.1, 0]]") {
  return R"({"name": "t", "objects": [{"name": "a", "path": )" + path +
         R"(, "end": 10, "beats": [)" + beats + "]}]}";
}

TEST(StoryTest, BadStoriesNameTheFileAndTheBeat) {
  EXPECT_NE(ErrorOf([] { ParseStory(StoryWith(""), "s.json"); }).find("s.json: objects[0].beats"),
            std::string::npos);
  const std::string unordered = ErrorOf([] {
    ParseStory(StoryWith(R"({"kind": "walk", "start": 0, "to": 1}, {"kind": "stand", "start": 0})"),
               "s.json");
  });
  EXPECT_NE(unordered.find("s.json: objects[0].beats[1].start"), std::string::npos) << unordered;
  EXPECT_NE(unordered.find("must increase"), std::string::npos) << unordered;
  const std::string unknown =
      ErrorOf([] { ParseStory(StoryWith(R"({"kind": "jmup", "start": 0, "to": 1})"), "s.json"); });
  EXPECT_NE(unknown.find("beats[0].kind"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("did you mean \"jump\""), std::string::npos) << unknown;
  const std::string off_table = ErrorOf([] {
    ParseStory(StoryWith(R"({"kind": "walk", "start": 0, "to": 1})", "[[0, 0], [0.6, 0]]"),
               "s.json");
  });
  EXPECT_NE(off_table.find("path[1]"), std::string::npos) << off_table;
  EXPECT_NE(off_table.find("inside the play area"), std::string::npos) << off_table;
  const std::string in_place_to =
      ErrorOf([] { ParseStory(StoryWith(R"({"kind": "stand", "start": 0, "to": 1})"), "s.json"); });
  EXPECT_NE(in_place_to.find("happens in place"), std::string::npos) << in_place_to;
  const std::string missing_to =
      ErrorOf([] { ParseStory(StoryWith(R"({"kind": "walk", "start": 0})"), "s.json"); });
  EXPECT_NE(missing_to.find("beats[0].to"), std::string::npos) << missing_to;
  const std::string misspelt = ErrorOf(
      [] { ParseStory(StoryWith(R"({"kind": "stand", "start": 0, "meanig": "x"})"), "s.json"); });
  EXPECT_NE(misspelt.find("did you mean \"meaning\""), std::string::npos) << misspelt;
  const std::string late_start =
      ErrorOf([] { ParseStory(StoryWith(R"({"kind": "stand", "start": 1})"), "s.json"); });
  EXPECT_NE(late_start.find("beats[0].start"), std::string::npos) << late_start;
  const std::string bad_target = ErrorOf([] {
    ParseStory(StoryWith(R"({"kind": "hit", "start": 0, "to": 1, "target": "ghost"})"), "s.json");
  });
  EXPECT_NE(bad_target.find("\"ghost\""), std::string::npos) << bad_target;
  EXPECT_NE(ErrorOf([] { ParseStory("{", "s.json"); }).find("s.json:1:2: invalid JSON"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] { LoadStory("/nonexistent/story.json"); }).find("/nonexistent/story.json"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::people
