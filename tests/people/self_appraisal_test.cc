// The animators' self-appraisal biases (people/self_appraisal.h): by hand.
#include "people/self_appraisal.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace mmh::people {
namespace {

using test_util::ErrorOf;

TEST(SelfAppraisalTest, BiasIsProgressPlusChoice) {
  SelfAppraisalOptions o;
  o.progress_weight = 0.2;
  o.choice_bonus = 0.05;
  // Three takes: progress 0, 1/2, 1; the montage, made last, 1 plus the choice bonus.
  EXPECT_DOUBLE_EQ(SelfAppraisalBias(o, 0, 3), 0.0);
  EXPECT_DOUBLE_EQ(SelfAppraisalBias(o, 1, 3), 0.1);
  EXPECT_DOUBLE_EQ(SelfAppraisalBias(o, 2, 3), 0.2);
  EXPECT_DOUBLE_EQ(SelfAppraisalBias(o, 3, 3), 0.25);
  // One take: it is the last one.
  EXPECT_DOUBLE_EQ(SelfAppraisalBias(o, 0, 1), 0.2);
  // Zero weights are the unbiased viewer (the hand-set people before the calibration).
  const SelfAppraisalOptions unbiased{.progress_weight = 0, .choice_bonus = 0};
  for (int item = 0; item <= 3; ++item) EXPECT_EQ(SelfAppraisalBias(unbiased, item, 3), 0.0);
}

TEST(SelfAppraisalTest, BadValuesAreErrors) {
  SelfAppraisalOptions o;
  o.choice_bonus = -0.1;
  EXPECT_NE(ErrorOf([&] { o.Validate("self_appraisal"); }).find("self_appraisal.choice_bonus"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { SelfAppraisalBias({}, 4, 3); }).find("montage (3)"), std::string::npos);
}

}  // namespace
}  // namespace mmh::people
