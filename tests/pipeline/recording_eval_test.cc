// EvaluateRecording (pipeline/recording_eval.h) on the committed real YCB-Video frames: the
// dataset's own poses as the estimate score perfectly, a dropped frame counts as a miss, and the
// mistakes a user makes are InputErrors naming the flag or key.
#include "pipeline/recording_eval.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/tum_io.h"
#include "tests/test_util.h"
#include "track/recording.h"

namespace mmh::pipeline {
namespace {

namespace fs = std::filesystem;
using test_util::ErrorOf;
using test_util::ListDir;
using test_util::TempDir;

const fs::path kReal = test_util::RealYcbvDir();
const fs::path kVideo = test_util::RealYcbvVideo();
const std::string kBrick = (kReal / "models" / "061_foam_brick.obj").string();

metrics::PoseEvaluationOptions WithoutVsd() {
  metrics::PoseEvaluationOptions options;
  options.vsd = false;  // VSD renders two depth images per frame; not what these tests are about
  return options;
}

// The brick's ground truth written as a TUM estimate, without the frames in `drop`.
std::string TruthAsEstimate(const TempDir& dir, std::vector<int> drop = {}) {
  const track::RecordingFrameSource recording(kVideo);
  const Trajectory truth = recording.Truth(21);
  Trajectory estimate;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (std::find(drop.begin(), drop.end(), static_cast<int>(i)) != drop.end()) continue;
    estimate.timestamps.push_back(truth.timestamps[i]);
    estimate.poses.push_back(truth.poses[i]);
  }
  const std::string path = (dir / "estimate.tum").string();
  WriteTum(path, estimate);
  return path;
}

// The brick of video 0000 with its truth as the estimate, as `mmh eval --input VIDEO --model BRICK
// --estimate FILE --set track.object=21` gives them.
RecordingEvalInputs BrickInputs(const TempDir& dir) {
  RecordingEvalInputs inputs;
  inputs.recording = kVideo.string();
  inputs.estimates = {TruthAsEstimate(dir)};
  inputs.models = {kBrick};
  return inputs;
}

RecordingEvalOptions Brick() {
  RecordingEvalOptions options;
  options.object = 21;
  return options;
}

TEST(RecordingEvalTest, TheTruthAsEstimateScoresPerfectly) {
  TempDir dir;
  const RecordingEvalInputs inputs = BrickInputs(dir);
  const RecordingEvalOptions options = Brick();
  const RecordingEvaluation result = EvaluateRecording(inputs, options, WithoutVsd());
  ASSERT_EQ(result.objects.size(), 1u);
  const metrics::BopRecall& r = result.objects[0].recall;
  EXPECT_EQ(r.frames, 10);
  EXPECT_NEAR(r.median_rotation_deg, 0.0, 1e-3);
  EXPECT_NEAR(r.median_translation, 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(r.recall_5deg_5cm, 1.0);
  EXPECT_DOUBLE_EQ(r.ar_mssd, 1.0);
  // The brick's symmetries come from the models_info.json beside its model.
  ASSERT_EQ(result.models_info.count(21), 1u);
  EXPECT_GT(result.objects[0].symmetries, 0);
}

TEST(RecordingEvalTest, AFrameWithoutEstimateIsAMiss) {
  TempDir dir;
  RecordingEvalInputs inputs;
  inputs.recording = kVideo.string();
  inputs.estimates = {"21=" + TruthAsEstimate(dir, {3})};
  inputs.models = {"21=" + kBrick};
  const RecordingEvaluation result = EvaluateRecording(inputs, {}, WithoutVsd());
  ASSERT_EQ(result.objects.size(), 1u);
  EXPECT_EQ(result.objects[0].object, 21);
  EXPECT_DOUBLE_EQ(result.objects[0].recall.recall_5deg_5cm, 0.9);
  EXPECT_FALSE(result.objects[0].frames[3].camera_T_estimate.has_value());
}

TEST(RecordingEvalTest, MistakesNameTheFlagOrKey) {
  TempDir dir;
  RecordingEvalInputs inputs = BrickInputs(dir);
  RecordingEvalOptions options = Brick();
  options.object = 99;
  EXPECT_NE(ErrorOf([&] { EvaluateRecording(inputs, options, WithoutVsd()); }).find("track.object"),
            std::string::npos);
  options.object = 0;  // the recording annotates three objects: which one?
  EXPECT_NE(ErrorOf([&] { EvaluateRecording(inputs, options, WithoutVsd()); }).find("0 (the only one)"),
            std::string::npos);
  options.object = 21;
  inputs.truth = inputs.estimates[0];  // --truth is for TUM folders only
  EXPECT_NE(ErrorOf([&] { EvaluateRecording(inputs, options, WithoutVsd()); }).find("--truth"),
            std::string::npos);
  inputs.truth.clear();
  inputs.estimates = {"21=" + inputs.estimates[0]};
  inputs.models = {"21=" + kBrick, "8=" + kBrick};  // no estimate for object 8
  EXPECT_NE(ErrorOf([&] { EvaluateRecording(inputs, options, WithoutVsd()); })
                .find("no estimate for object 8"),
            std::string::npos);
  inputs.models = {kBrick};
  inputs.recording = (dir / "nowhere").string();
  EXPECT_NE(ErrorOf([&] { EvaluateRecording(inputs, options, WithoutVsd()); }).find("--input"),
            std::string::npos);
}

TEST(RecordingEvalTest, TheFolderIsWrittenWhole) {
  TempDir dir;
  const RecordingEvalInputs inputs = BrickInputs(dir);
  const RecordingEvaluation result = EvaluateRecording(inputs, Brick(), WithoutVsd());
  const fs::path out = dir / "eval";
  WriteRecordingEvaluation(out, result, inputs, {{"track", 1}}, {{"writer", "mmh"}});
  EXPECT_EQ(ListDir(out),
            (std::vector<std::string>{"config.resolved.json", "eval.json", "eval_frames.csv",
                                      "eval_objects.csv", "eval_overall.csv", "run.json"}));
  const auto json = nlohmann::json::parse(test_util::ReadBytes(out / "eval.json"));
  EXPECT_EQ(json["objects"][0]["object"], 21);
  EXPECT_EQ(json["models_info"]["21"], (kReal / "models" / "models_info.json").string());
  // A folder mmh did not write is not replaced.
  const fs::path foreign = dir / "foreign";
  fs::create_directories(foreign);
  test_util::WriteText(foreign / "notes.txt", "mine");
  EXPECT_THROW(WriteRecordingEvaluation(foreign, result, inputs, {}, {{"writer", "mmh"}}),
               InputError);
  EXPECT_EQ(ListDir(foreign), std::vector<std::string>{"notes.txt"});
}

}  // namespace
}  // namespace mmh::pipeline
