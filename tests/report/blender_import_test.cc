// A .glb written by `mmh export` opens in Blender's own glTF importer (Debian `blender`, headless,
// report/web/tools/blender_check.py) with one keyframe per frame and the object at the TUM pose of
// a chosen frame. Blender converts glTF's +Y up to its +Z up, so its world frame is our table
// frame; it also converts the mesh's vertices (p -> table_T_gltf p), so the object's rotation is
// table_T_proxy * gltf_T_table (docs/notation.md, "glTF export").
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "core/tum_io.h"
#include "report/gltf_scene.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

TEST(BlenderImport, FrameRangeAndPoseAtAChosenFrame) {
  if (std::system("command -v blender >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "Debian blender is not installed (./mmh installs it)";
  }
  test_util::TempDir dir;
  const std::string source = MMH_SOURCE_DIR;
  const std::string tum = source + "/examples/synthetic_story/take_2.tum";
  const auto glb = dir / "take_2.glb";
  const auto r = test_util::RunMmh("export --quiet --trajectory " + tum + " --model " + source +
                                   "/configs/proxies/soldier.json --out " + glb.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Trajectory take = ReadTum(tum);
  const std::vector<int> frames = {0, 77, static_cast<int>(take.size()) - 1};
  const std::string command = "blender -b --factory-startup --python-exit-code 2 -P " + source +
                              "/report/web/tools/blender_check.py -- " + glb.string() +
                              " 30 0,77," + std::to_string(frames[2]) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
  ASSERT_EQ(pclose(pipe), 0) << output;
  const auto at = output.find("MMH_BLENDER_RESULT ");
  ASSERT_NE(at, std::string::npos) << output;
  const auto result =
      nlohmann::json::parse(output.substr(at + 19, output.find('\n', at) - at - 19));
  ASSERT_TRUE(result["objects"].contains("take_2")) << result.dump(1);
  const auto& object = result["objects"]["take_2"];
  // One keyframe per frame at 30 frames/s.
  EXPECT_NEAR(object["frame_end"].get<double>() - object["frame_start"].get<double>(),
              static_cast<double>(take.size() - 1), 1e-3);
  for (const auto& pose : object["poses"]) {
    const Rigid3& expected = take.poses[pose["frame"].get<int>()];
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(pose["translation"][c].get<double>(), expected.translation(c), 1e-5)
          << "frame " << pose["frame"];
    }
    const auto& q = pose["quaternion_wxyz"];
    const Eigen::Quaterniond blender(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(),
                                     q[3].get<double>());
    const Eigen::Quaterniond expected_blender =
        expected.rotation * report::GltfTFrame(report::TrajectoryFrame::kTable).rotation;
    EXPECT_LT(RotationAngle(blender, expected_blender), 1e-5) << "frame " << pose["frame"];
  }
}

}  // namespace
}  // namespace mmh
