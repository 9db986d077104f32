// The population: reproducible participants inside the documented ranges.
#include "people/population.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::people {
namespace {

TEST(PopulationTest, ParticipantsAreReproducibleAndInRange) {
  const PopulationOptions population;
  double skill = 0;
  for (int i = 0; i < 200; ++i) {
    const Participant p = DrawParticipant(population, i);
    EXPECT_EQ(p.index, i);
    p.animator.Validate("animator");
    p.annotator.Validate("annotator");
    EXPECT_GE(p.annotator.reaction_delay, 0.25);
    EXPECT_LE(p.annotator.reaction_delay, 0.35);
    skill += p.animator.skill / 200;
  }
  EXPECT_NEAR(skill, population.skill_mean, 0.05);
  EXPECT_EQ(DrawParticipant(population, 7).animator.skill,
            DrawParticipant(population, 7).animator.skill);
  PopulationOptions other = population;
  other.seed = 2;
  EXPECT_NE(DrawParticipant(other, 7).animator.skill,
            DrawParticipant(population, 7).animator.skill);
  EXPECT_NE(ParticipantSeed(population, 1), ParticipantSeed(population, 2));
}

TEST(PopulationTest, BadOptionsNameTheField) {
  PopulationOptions population;
  population.delay_mean = 0.5;
  EXPECT_NE(
      test_util::ErrorOf([&] { DrawParticipant(population, 0); }).find("population.delay_mean"),
      std::string::npos);
}

}  // namespace
}  // namespace mmh::people
