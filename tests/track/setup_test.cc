// The setup calibration file (scene.json keys).
#include "track/setup.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace mmh::track {
namespace {

using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

constexpr const char* kTable =
    R"("table": {"play_area_width": 0.5, "play_area_depth": 0.3, "like_box_center_x": 0.36,
       "like_box_center_y": -0.05, "like_box_length": 0.16, "like_box_width": 0.06, "backdrop": true})";

TEST(SetupTest, ReadsTheRenderersSceneJson) {
  TempDir dir;
  WriteText(dir / "scene.json", std::string("{\"camera_T_table\": {\"translation\": [0, 0, 1.2], "
                                            "\"quaternion_xyzw\": [0, 0, 0, 1]}, ") +
                                    kTable + ", \"slider_block_size\": 0.03}");
  const TrackSetup setup = ReadSetupJson(dir / "scene.json");
  ASSERT_TRUE(setup.camera_T_table);
  EXPECT_DOUBLE_EQ(setup.camera_T_table->translation.z(), 1.2);
  EXPECT_DOUBLE_EQ(setup.play_area_width, 0.5);
  EXPECT_DOUBLE_EQ(setup.slider_block_size, 0.03);
  EXPECT_TRUE(setup.has_like_box());
  // Without a camera pose.
  WriteText(dir / "plain.json", std::string("{") + kTable + "}");
  EXPECT_FALSE(ReadSetupJson(dir / "plain.json").camera_T_table);
}

TEST(SetupTest, BadFilesNameTheKey) {
  TempDir dir;
  WriteText(dir / "a.json", "{\"table\": {\"play_area_width\": 0.5}}");
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "a.json"); }), HasSubstr("'play_area_depth'"));
  WriteText(dir / "b.json", std::string("{\"camera_T_table\": {\"translation\": [0, 0], "
                                        "\"quaternion_xyzw\": [0, 0, 0, 1]}, ") +
                                kTable + "}");
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "b.json"); }), HasSubstr("an array of 3 numbers"));
  WriteText(dir / "c.json", std::string("{\"camera_T_table\": {\"translation\": [0, 0, 1], "
                                        "\"quaternion_xyzw\": [0, 0, 0, 2]}, ") +
                                kTable + "}");
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "c.json"); }), HasSubstr("unit quaternion"));
  WriteText(dir / "d.json", "{\"table\": ");
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "d.json"); }), HasSubstr("invalid JSON"));
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "none.json"); }),
              HasSubstr("none.json: got a path that does not exist"));
  WriteText(dir / "e.json",
            R"({"table": {"play_area_width": 0.5, "play_area_depth": 0.3, "like_box_center_x": 0.36,
       "like_box_center_y": -0.05, "like_box_length": 0.02, "like_box_width": 0.06}})");
  EXPECT_THAT(ErrorOf([&] { ReadSetupJson(dir / "e.json"); }), HasSubstr("like_box_length"));
}

}  // namespace
}  // namespace mmh::track
