// The scenario section and the people's config: read from the sections, written back whole, and
// the keys that moved from "render" refused with their new name and the file they are in.
#include "people/scenario.h"

#include <gtest/gtest.h>

#include "core/config.h"
#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

TEST(ScenarioTest, ReadsTheFourSectionsAndWritesThemBack) {
  Config config;
  config.Set("scenario.story=\"configs/stories/mario.json\"");
  config.Set("scenario.object=1");
  config.Set("scenario.animator=7");
  config.Set("population.seed=3");
  config.Set("performance.frame_rate=15");
  config.Set("annotator.start_value=2");
  const PeopleConfig people = PeopleConfig::FromConfig(config);
  EXPECT_EQ(people.scenario.story, "configs/stories/mario.json");
  EXPECT_EQ(people.scenario.object, 1);
  EXPECT_EQ(people.scenario.animator, 7);
  EXPECT_EQ(people.population.seed, 3u);
  EXPECT_EQ(people.performance.frame_rate, 15.0);
  EXPECT_EQ(people.annotator.start_value, 2.0);

  nlohmann::json json;
  people.AddToJson(json);
  EXPECT_EQ(json["scenario"]["animator"], 7);
  EXPECT_EQ(json["population"]["seed"], 3);
  // The resolved sections read back to the same config.
  Config again;
  for (const auto& [section, value] : json.items()) again.Set(section + "=" + value.dump());
  nlohmann::json round_trip;
  PeopleConfig::FromConfig(again).AddToJson(round_trip);
  EXPECT_EQ(round_trip, json);
}

TEST(ScenarioTest, DefaultsAreNoStoryAndTheFirstParticipant) {
  const PeopleConfig people = PeopleConfig::FromConfig(Config());
  EXPECT_TRUE(people.scenario.story.empty());
  EXPECT_EQ(people.scenario.object, 0);
  EXPECT_EQ(people.scenario.animator, 0);
}

TEST(ScenarioTest, KeysThatMovedFromRenderNameTheFileAndTheNewKey) {
  const test_util::TempDir dir;
  const std::filesystem::path file = dir.path() / "old.json";
  test_util::WriteText(file, R"({"render": {"story": "configs/stories/soldier.json"}})");
  const std::string error =
      test_util::ErrorOf([&] { PeopleConfig::FromConfig(Config::Load(file)); });
  EXPECT_NE(error.find(file.string()), std::string::npos) << error;
  EXPECT_NE(error.find("'render.story' has moved to 'scenario.story'"), std::string::npos)
      << error;
  Config set;
  set.Set("render.animator=2");
  const std::string set_error = test_util::ErrorOf([&] { PeopleConfig::FromConfig(set); });
  EXPECT_NE(set_error.find("--set render.animator=2: key 'render.animator' has moved to "
                           "'scenario.animator'"),
            std::string::npos)
      << set_error;
}

TEST(ScenarioTest, BadValuesNameTheKey) {
  Config story;
  story.Set("scenario.story=\"soldier.txt\"");
  EXPECT_NE(test_util::ErrorOf([&] { PeopleConfig::FromConfig(story); }).find("scenario.story"),
            std::string::npos);
  Config animator;
  animator.Set("scenario.animator=-1");
  EXPECT_NE(
      test_util::ErrorOf([&] { PeopleConfig::FromConfig(animator); }).find("scenario.animator"),
      std::string::npos);
  Config unknown;
  unknown.Set("scenario.take=1");
  EXPECT_NE(test_util::ErrorOf([&] { PeopleConfig::FromConfig(unknown); }).find("scenario.take"),
            std::string::npos);
}

}  // namespace
}  // namespace mmh::people
