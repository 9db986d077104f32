#include "core/table_setup.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace mmh {
namespace {

// The slider's definition, from the geometry rather than the formula: at -5 the block's left edge
// touches the Like box's left end, at +5 its right edge the right end, linear in between.
TEST(TableSetup, SliderEndsTouchTheLikeBoxEnds) {
  TableSetup setup;
  setup.like_box_center_x = 0.31;
  setup.like_box_length = 0.2;
  setup.slider_block_size = 0.04;
  const double box_left = setup.like_box_center_x - setup.like_box_length / 2;
  const double box_right = setup.like_box_center_x + setup.like_box_length / 2;
  EXPECT_NEAR(setup.SliderCenterX(-5) - setup.slider_block_size / 2, box_left, 1e-15);
  EXPECT_NEAR(setup.SliderCenterX(5) + setup.slider_block_size / 2, box_right, 1e-15);
  EXPECT_NEAR(setup.SliderCenterX(0), setup.like_box_center_x, 1e-15);
  // Linear: equal value steps, equal distances (0.08 m of travel over 10 units).
  for (double v = -5; v < 5; v += 0.5) {
    EXPECT_NEAR(setup.SliderCenterX(v + 0.5) - setup.SliderCenterX(v), 0.5 * 0.16 / 10, 1e-15);
  }
}

TEST(TableSetup, SliderValueInvertsTheCentreAndIsNotClamped) {
  const TableSetup setup;
  for (double v = -7; v <= 7; v += 0.25) {
    EXPECT_NEAR(setup.SliderValue(setup.SliderCenterX(v)), v, 1e-12) << v;
  }
  EXPECT_GT(setup.SliderValue(1.0), 5.0);
  EXPECT_LT(setup.SliderValue(-1.0), -5.0);
}

TEST(TableSetup, ValidateNamesTheField) {
  EXPECT_NO_THROW(TableSetup{}.Validate("scene"));
  TableSetup no_box;
  no_box.like_box_length = 0;
  EXPECT_FALSE(no_box.has_like_box());
  EXPECT_NO_THROW(no_box.Validate("setup"));

  TableSetup short_box;
  short_box.like_box_length = 0.03;  // shorter than the 31.8 mm block
  try {
    short_box.Validate("setup");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("setup.like_box_length"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slider_block_size"), std::string::npos) << e.what();
  }
  TableSetup bad_area;
  bad_area.play_area_depth = -0.1;
  EXPECT_THROW(bad_area.Validate("setup"), InputError);
  TableSetup nan_centre;
  nan_centre.like_box_center_y = std::nan("");
  EXPECT_THROW(nan_centre.Validate("setup"), InputError);
}

}  // namespace
}  // namespace mmh
