// ComposeToFolder (montage/compose_folder.h): the folder holds exactly what Compose and
// ComposeLayered compute, read back through the project's own readers; bad input leaves nothing.
#include "montage/compose_folder.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/annotation.h"
#include "core/error.h"
#include "core/tum_io.h"
#include "tests/test_util.h"
#include "tools/synthetic_takes.h"

namespace mmh::montage {
namespace {

using test_util::ListDir;
using test_util::ReadBytes;
using test_util::TempDir;

// Three short synthetic takes written as files, as `mmh compose` reads them.
struct TakeFiles {
  std::vector<std::string> takes, annotations;
};

TakeFiles WriteTakes(const TempDir& dir, int count, int frames, std::uint64_t seed,
                     const std::string& prefix) {
  synthetic::TakeSetOptions options;
  options.takes = count;
  options.reference_frames = frames;
  options.min_frames = frames - 20;
  options.max_frames = frames + 20;
  options.seed = seed;
  const synthetic::TakeSet set = synthetic::MakeTakeSet(options);
  TakeFiles files;
  for (int k = 0; k < count; ++k) {
    files.takes.push_back((dir / (prefix + std::to_string(k) + ".tum")).string());
    files.annotations.push_back((dir / (prefix + std::to_string(k) + ".csv")).string());
    WriteTum(files.takes.back(), set.takes[k]);
    WriteAnnotationCsv(files.annotations.back(), set.annotations[k]);
  }
  return files;
}

ComposeOptions SmallOptions() {
  ComposeOptions options;
  options.labelling.min_segment_length = 20;
  return options;
}

TEST(ComposeFolderTest, FilesHoldTheMontageComposeComputes) {
  TempDir dir;
  const TakeFiles files = WriteTakes(dir, 3, 240, 7, "take_");
  const ComposeObjectInput input = ReadComposeObject("proxy", files.takes, files.annotations);
  ASSERT_EQ(input.object.takes.size(), 3u);
  ASSERT_EQ(input.object.names.size(), 6u);

  ComposeFolderOptions folder;
  folder.marker_frames = {5, 100};
  nlohmann::json seen_timings;
  folder.provenance = [&](const nlohmann::json& resolved, const nlohmann::json& timings) {
    EXPECT_TRUE(resolved.contains("montage"));
    seen_timings = timings;
    return nlohmann::json{{"writer", "mmh"}};
  };
  int glb_calls = 0;
  folder.glb = [&](const std::vector<Montage>& montages) {
    ++glb_calls;
    EXPECT_EQ(montages.size(), 1u);
    return std::string("glTF-bytes");
  };
  const auto out = dir / "out";
  const ComposeFolderResult result = ComposeToFolder({input}, SmallOptions(), out, folder);

  // The same montage as the compositor called directly.
  const Montage direct = Compose(input.object.takes, input.object.annotations, SmallOptions());
  ASSERT_EQ(result.montages.size(), 1u);
  EXPECT_EQ(result.montages[0].trajectory.timestamps, direct.trajectory.timestamps);
  EXPECT_EQ(ReadBytes(out / "segments.csv"), SegmentsToCsv(direct.segments));
  EXPECT_EQ(ReadBytes(out / "timeline.csv"), TimelineToCsv(direct));
  const Trajectory montage = ReadTum(out / "montage.tum");
  ASSERT_EQ(montage.size(), direct.trajectory.size());
  for (std::size_t i = 0; i < montage.size(); ++i) {
    EXPECT_NEAR((montage.poses[i].translation - direct.trajectory.poses[i].translation).norm(), 0.0,
                1e-6);
  }
  // Markers: the montage's poses at the marked frames.
  const Trajectory markers = ReadTum(out / "markers.tum");
  ASSERT_EQ(markers.size(), 2u);
  EXPECT_DOUBLE_EQ(markers.timestamps[1], direct.trajectory.timestamps[100]);
  EXPECT_NEAR((markers.poses[1].translation - direct.trajectory.poses[100].translation).norm(),
              0.0, 1e-6);

  EXPECT_EQ(glb_calls, 1);
  EXPECT_EQ(ReadBytes(out / "montage.glb"), "glTF-bytes");
  // Timings go to run.json only: summary.json is a pure function of the inputs.
  const nlohmann::json summary = nlohmann::json::parse(ReadBytes(out / "summary.json"));
  EXPECT_FALSE(summary.contains("seconds"));
  EXPECT_TRUE(seen_timings.contains("total"));
  EXPECT_EQ(summary["take_files"], nlohmann::json(files.takes));
  EXPECT_EQ(ListDir(out), (std::vector<std::string>{"config.resolved.json", "markers.tum",
                                                   "montage.glb", "montage.tum", "run.json",
                                                   "segments.csv", "summary.json",
                                                   "timeline.csv"}));
  EXPECT_EQ(result.written,
            (std::vector<std::string>{"montage.tum", "segments.csv", "timeline.csv",
                                      "summary.json", "config.resolved.json", "run.json",
                                      "markers.tum", "montage.glb"}));
}

TEST(ComposeFolderTest, LayeredObjectsGetTheirOwnFolders) {
  TempDir dir;
  const TakeFiles first = WriteTakes(dir, 2, 200, 3, "a_");
  // A layered object's takes have equal lengths (recorded while the first montage played).
  const TakeFiles second = WriteTakes(dir, 1, 200, 4, "b_");
  const TakeFiles layered{{second.takes[0], second.takes[0]},
                          {second.annotations[0], second.annotations[0]}};
  const std::vector<ComposeObjectInput> objects = {
      ReadComposeObject("proxy", first.takes, first.annotations),
      ReadComposeObject("hat", layered.takes, layered.annotations)};
  const auto out = dir / "out";
  const ComposeFolderResult result = ComposeToFolder(objects, SmallOptions(), out, {});
  ASSERT_EQ(result.montages.size(), 2u);
  EXPECT_EQ(ReadBytes(out / "layers" / "hat" / "segments.csv"),
            SegmentsToCsv(result.montages[1].segments));
  const nlohmann::json layer =
      nlohmann::json::parse(ReadBytes(out / "layers" / "hat" / "summary.json"));
  EXPECT_EQ(layer["name"], "hat");
  const nlohmann::json summary = nlohmann::json::parse(ReadBytes(out / "summary.json"));
  EXPECT_EQ(summary["layers"][0]["folder"], "layers/hat");
  EXPECT_FALSE(std::filesystem::exists(out / "montage.glb"));  // no glb callback
}

TEST(ComposeFolderTest, BadInputLeavesNothing) {
  TempDir dir;
  const TakeFiles files = WriteTakes(dir, 2, 200, 5, "take_");
  const ComposeObjectInput input = ReadComposeObject("proxy", files.takes, files.annotations);
  const auto out = dir / "out";
  ComposeFolderOptions folder;
  folder.marker_frames = {10, 30};  // closer than the paper's 60 frames
  EXPECT_THROW(ComposeToFolder({input}, SmallOptions(), out, folder), InputError);
  folder.marker_frames = {100000};  // past the montage's end
  EXPECT_THROW(ComposeToFolder({input}, SmallOptions(), out, folder), InputError);
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(ListDir(dir.path()).size(), 4u);  // the inputs only: no staging folder left
  // A file that does not exist is named.
  const std::string error = test_util::ErrorOf(
      [&] { ReadComposeObject("proxy", {(dir / "missing.tum").string()}, files.annotations); });
  EXPECT_NE(error.find("missing.tum"), std::string::npos) << error;
}

}  // namespace
}  // namespace mmh::montage
