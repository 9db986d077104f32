// `mmh track` and `mmh eval` on the committed real YCB-Video frames (tests/data/real/ycbv): the
// gelatin box, the foam brick and the mug tracked from the ground truth's first pose, scored by `mmh eval` against the dataset's poses; and the bad inputs
// the issue names (a model 1000 times too big, a recording without a depth scale, inconsistent
// ground truth): exit code 2 with the file and the value.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>
#include <vector>

#include "core/image_io.h"
#include "core/tum_io.h"
#include "metrics/tracking_metrics.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

const fs::path kReal = test_util::RealYcbvDir();
const fs::path kVideo = test_util::RealYcbvVideo();
const std::string kPreset = std::string(MMH_SOURCE_DIR) + "/configs/track_real.json";

struct Scores {
  double median_rotation_deg, median_translation_mm, recall_5deg_5cm, ar;
};

// The bounds are the figures measured on 2026-11-28 at 9f2f81e (docs/tracker.md, "The sim-to-real
// gap", the same commands) with a margin in the worse direction only: a run is deterministic (the
// same input gives the same trajectory), so the margin covers other compilers and library
// versions and small intended changes, not noise: 0.5 deg of median rotation and 0.5 mm of median
// translation (a quarter of the 2 deg goal; the largest shift any of the preset's
// options made to another object's medians was 0.13 deg / 0.04 mm), one frame of ten in the
// recall within 5 deg / 5 cm, and 0.02 of BOP's AR (a fifth of one frame's AR at 10 frames).
constexpr double kRotationMarginDeg = 0.5, kTranslationMarginMm = 0.5, kRecallMargin = 0.1,
                 kArMargin = 0.02;

void ExpectNoWorseThan(const Scores& got, const Scores& measured) {
  EXPECT_LT(got.median_rotation_deg, measured.median_rotation_deg + kRotationMarginDeg);
  EXPECT_LT(got.median_translation_mm, measured.median_translation_mm + kTranslationMarginMm);
  EXPECT_GE(got.recall_5deg_5cm, measured.recall_5deg_5cm - kRecallMargin);
  EXPECT_GE(got.ar, measured.ar - kArMargin);
}

// `model` under tests/data/real/ycbv (models/: the fitted cuboids; models_real/: the hulls of the
// dataset's own model points), `video` a folder of it, `extra` more flags for `mmh track`.
// `tag` names the output folders apart when one test tracks several recordings' same object;
// `frames` is the recording's length (default: 10 for video 0000, else 1).
Scores TrackAndEval(const TempDir& dir, int object, const std::string& model, const std::string& init,
                    const fs::path& video = kVideo, const std::string& extra = "",
                    const std::string& tag = "", int frames = 0) {
  const fs::path out = dir / (tag + "track_" + init + std::to_string(object));
  const auto track = RunMmh("track --quiet --input " + video.string() + " --model " +
                            (kReal / model).string() + " --config " + kPreset +
                            " --set track.object=" + std::to_string(object) +
                            " --set track.init=\\\"" + init + "\\\" " + extra + " --out " +
                            out.string());
  EXPECT_EQ(track.exit_code, 0) << track.output;
  const auto summary = nlohmann::json::parse(ReadBytes(out / "track_summary.json"));
  EXPECT_EQ(summary["init"], init);
  EXPECT_TRUE(fs::exists(out / "groundtruth.tum"));
  const fs::path eval = dir / (tag + "eval_" + init + std::to_string(object));
  const auto result = RunMmh("eval --quiet --input " + video.string() + " --model " +
                             (kReal / model).string() + " --estimate " +
                             (out / "trajectory.tum").string() + " --set track.object=" +
                             std::to_string(object) + " --out " + eval.string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(ReadBytes(eval / "eval.json"));
  const auto& o = json["objects"][0];
  EXPECT_EQ(o["frames"], frames > 0 ? frames : video == kVideo ? 10 : 1);
  EXPECT_FALSE(o["ar_vsd"].is_null());
  return {o["median_rotation_deg"], o["median_translation_mm"], o["recall_5deg_5cm"], o["ar"]};
}

TEST(RealRecordingCliTest, TracksYcbVideoObjectsFromTheTruthsFirstPose) {
  TempDir dir;
  // Measured (median rotation deg, translation mm, recall within 5 deg / 5 cm, AR): the box
  // 1.209, 1.706, 1.0, 1.000; the brick 2.470, 1.967, 1.0, 0.978.
  for (const auto& [object, model, measured] :
       {std::tuple<int, std::string, Scores>{8, "models/009_gelatin_box.obj", {1.209, 1.706, 1.0, 1.0}},
        {21, "models/061_foam_brick.obj", {2.470, 1.967, 1.0, 0.978}}}) {
    SCOPED_TRACE(model);
    ExpectNoWorseThan(TrackAndEval(dir, object, model, "truth"), measured);
  }
}

// The real view rendered (docs/tracker.md, "Like for like: the real view rendered"): the gelatin
// box with its real shape where the dataset's truth puts it on the table, seen from the real
// camera's place (tests/data/real/ycbv/views, written by render_real_view.py), in both sensor
// modes, tracked and scored as the real frames are. The real frames are the oracle of the sensor
// model here: rendered frames must not give the tracker more error than the real ones (the model
// would then over-state the sensor), and structured light must be the nearer of the two modes
// (docs/sensor.md's claim). Measured (the view with the mug, the foam brick and the desk's
// clutter): real 1.54 deg / 0.89 mm, structured light 0.40 deg / 0.27 mm, statistical 0.21 deg /
// 0.14 mm.
TEST(RealRecordingCliTest, TheRealViewRenderedGivesTheTrackerNoMoreErrorThanTheRealFrames) {
  TempDir dir;
  const std::string model = "models_real/009_gelatin_box.obj";
  const Scores real = TrackAndEval(dir, 8, model, "truth");
  auto rendered = [&](const std::string& mode) {
    const fs::path render = dir / ("render_" + mode);
    const auto r = RunMmh("render --quiet --config " +
                          (kReal / "views" / "009_gelatin_box_static.json").string() +
                          " --set render.proxy=\\\"" + (kReal / model).string() +
                          "\\\" --set render.trajectory=\\\"" +
                          (kReal / "views" / "009_gelatin_box_static.tum").string() +
                          "\\\" --set sensor.mode=\\\"" + mode + "\\\" --out " + render.string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return TrackAndEval(dir, 1, model, "truth", render / "bop", "", mode, 10);
  };
  const Scores structured = rendered("structured_light");
  const Scores statistical = rendered("statistical");
  EXPECT_LE(structured.median_rotation_deg, real.median_rotation_deg);
  EXPECT_LE(structured.median_translation_mm, real.median_translation_mm);
  EXPECT_LE(statistical.median_rotation_deg, real.median_rotation_deg);
  EXPECT_LE(statistical.median_translation_mm, real.median_translation_mm);
  EXPECT_LT(real.median_rotation_deg - structured.median_rotation_deg,
            real.median_rotation_deg - statistical.median_rotation_deg);
  EXPECT_LT(real.median_translation_mm - structured.median_translation_mm,
            real.median_translation_mm - statistical.median_translation_mm);
}

// The desk's clutter in the committed views (models_real/desk_clutter_0000.obj: the keyboard, the
// mouse and the monitor's foot, meshed from frame 1's depth by render_real_view.py --clutter)
// stands on the real frame's pixels: the view rendered without noise through the real colour
// camera's pinhole gives the real depth there to a few millimetres (measured: median 0.8 mm, 98 %
// within 1 cm), where the view without it sees the desk below (the keyboard is 1.6-3.7 cm high).
TEST(RealRecordingCliTest, TheViewsClutterStandsOnTheRealFramesPixels) {
  TempDir dir;
  const fs::path view = kReal / "views" / "009_gelatin_box_static.json";
  // The same view without the clutter, its meshes' paths made absolute.
  nlohmann::json bare = nlohmann::json::parse(ReadBytes(view));
  nlohmann::json objects = nlohmann::json::array();
  for (nlohmann::json object : bare["scene"]["objects"]) {
    if (object["name"] == "clutter") continue;
    object["mesh"] = fs::weakly_canonical(view.parent_path() / object["mesh"].get<std::string>());
    objects.push_back(object);
  }
  ASSERT_EQ(objects.size() + 1, bare["scene"]["objects"].size()) << "the view has its clutter";
  bare["scene"]["objects"] = objects;
  WriteText(dir / "bare.json", bare.dump());
  auto render = [&](const fs::path& config, const std::string& name) {
    const auto r = RunMmh(
        "render --quiet --config " + config.string() + " --set render.proxy=\\\"" +
        (kReal / "models_real/009_gelatin_box.obj").string() + "\\\" --set render.trajectory=\\\"" +
        (kReal / "views" / "009_gelatin_box_static.tum").string() +
        "\\\" --set sensor.mode=\\\"statistical\\\" --set sensor.noise=false --set render.frames=1 "
        "--set 'sensor.intrinsics={\"width\":640,\"height\":480,\"fx\":1066.778,\"fy\":1067.487,"
        "\"cx\":312.9869,\"cy\":241.3109}' --out " +
        (dir / name).string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return ReadDepthPng16(dir / name / "depth" / "0.000000.png");
  };
  const DepthImage with = render(view, "with"), without = render(dir / "bare.json", "without");
  const DepthImage real = ReadDepthPng16(kVideo / "000001-depth.png");  // 1/10000 m
  const RgbImage label = ReadRgbImage(kVideo / "000001-label.png");
  ASSERT_EQ(with.values.size(), real.values.size());
  ASSERT_EQ(label.rgb.size(), 3 * real.values.size());
  std::vector<double> errors, desk_errors;
  for (size_t p = 0; p < real.values.size(); ++p) {
    const double a = with.values[p] / 5000.0, b = without.values[p] / 5000.0;
    const double measured = real.values[p] / 10000.0;
    // The clutter's pixels: off the labelled objects, nearer with it than without by 5 mm.
    if (label.rgb[3 * p] != 0 || !(a > 0) || !(b > 0) || !(measured > 0) || a > b - 0.005) continue;
    errors.push_back(std::abs(a - measured));
    desk_errors.push_back(std::abs(b - measured));
  }
  ASSERT_GT(errors.size(), 20000u) << "the keyboard alone covers about 30 000 pixels";
  const double within =
      std::count_if(errors.begin(), errors.end(), [](double e) { return e < 0.01; }) /
      static_cast<double>(errors.size());
  EXPECT_LT(metrics::Quantile(errors, 0.5), 0.002);
  EXPECT_GT(within, 0.95);
  EXPECT_GT(metrics::Quantile(desk_errors, 0.5), 0.01);
}

TEST(RealRecordingCliTest, TracksYcbVideoObjectsFromItsOwnDetection) {
  TempDir dir;
  // The detection among the model-sized segments (configs/track_real.json). Measured: gelatin box
  // 1.247 deg / 1.730 mm, brick 2.374 deg / 1.593 mm (errors against the nearest symmetric truth,
  // models/models_info.json: the detection picks a half turn of the brick's square prism), all 10
  // frames within 5 deg / 5 cm, AR 1.000 and 0.979. The box meets the goals (median
  // <= 2 deg, <= 5 mm, >= 90 % within 5 deg / 5 cm, and its bound is inside them); the brick
  // misses the 2 deg, where the truth and the depth disagree (2.47 deg from the truth's first
  // pose, 2.46 with the real shape: docs/tracker.md).
  const Scores box = TrackAndEval(dir, 8, "models/009_gelatin_box.obj", "detection");
  ExpectNoWorseThan(box, {1.247, 1.730, 1.0, 1.0});
  const Scores brick = TrackAndEval(dir, 21, "models/061_foam_brick.obj", "detection");
  ExpectNoWorseThan(brick, {2.374, 1.593, 1.0, 0.979});

  // Both objects in one call from the runs' BOP result files: the same per-object figures (R to
  // 9 digits), and the pooled row weighs them by frames.
  std::string both = ReadBytes(dir / "track_detection8" / "results_bop.csv");
  const std::string brick_results = ReadBytes(dir / "track_detection21" / "results_bop.csv");
  both += brick_results.substr(brick_results.find('\n') + 1);
  // Each line's time is the frame's own tracking time (seconds, measured): positive, the first
  // frame's (the detection) the longest.
  std::vector<double> times;
  std::istringstream lines(brick_results);
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) times.push_back(std::stod(line.substr(line.rfind(',') + 1)));
  ASSERT_EQ(times.size(), 10u);
  for (double t : times) EXPECT_GT(t, 0.0);
  EXPECT_EQ(std::max_element(times.begin(), times.end()) - times.begin(), 0);
  WriteText(dir / "both.csv", both);
  const auto result = RunMmh("eval --quiet --input " + kVideo.string() + " --model 8=" +
                             (kReal / "models" / "009_gelatin_box.obj").string() + " --model 21=" +
                             (kReal / "models" / "061_foam_brick.obj").string() + " --estimate " +
                             (dir / "both.csv").string() + " --out " + (dir / "both").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(ReadBytes(dir / "both" / "eval.json"));
  ASSERT_EQ(json["objects"].size(), 2u);
  EXPECT_NEAR(json["objects"][0]["median_rotation_deg"].get<double>(), box.median_rotation_deg, 1e-4);
  EXPECT_NEAR(json["objects"][1]["ar"].get<double>(), brick.ar, 1e-9);
  EXPECT_EQ(json["overall"]["frames"], 20);
  EXPECT_NEAR(json["overall"]["ar"].get<double>(), (box.ar + brick.ar) / 2, 1e-9);
  EXPECT_TRUE(fs::exists(dir / "both" / "eval_overall.csv"));
}

// The hulls of the dataset's own model points (models_real/, PROVENANCE.md) instead of the fitted
// cuboids, from the truth's first pose. Measured: gelatin box 1.538 deg / 0.891 mm, all 10
// frames within 5 deg / 5 cm, AR 1.000; foam brick 2.465 deg / 1.413 mm, 10 of 10, AR 0.990 (the
// cuboid: 2.47 deg / 1.97 mm, AR 0.978): the brick's 2.5 deg stays with the real shape
// (docs/tracker.md, "The sim-to-real gap").
TEST(RealRecordingCliTest, TracksYcbVideoObjectsWithTheirRealModelPoints) {
  TempDir dir;
  ExpectNoWorseThan(TrackAndEval(dir, 8, "models_real/009_gelatin_box.obj", "truth"),
                    {1.538, 0.891, 1.0, 1.0});
  ExpectNoWorseThan(TrackAndEval(dir, 21, "models_real/061_foam_brick.obj", "truth"),
                    {2.465, 1.413, 1.0, 0.990});
}

// A can (a cylinder: continuous symmetry about its axis, models_real/models_info.json) found by
// the tracker's own detection on a real frame among a sugar box, a meat can and a pitcher.
// Measured 1.844 deg / 2.398 mm, within 5 deg / 5 cm, AR 0.967 (one frame: the recall margin
// leaves none). The table check is widened to 2 cm: on this frame the
// dataset's own truth puts the can's bottom 10.6 mm below the table plane that the table's pixels
// beside it confirm to 1 mm (docs/tracker.md), and the 1 cm default rejects the true pose.
TEST(RealRecordingCliTest, FindsACanOnARealFrameFromItsOwnDetection) {
  TempDir dir;
  const Scores can = TrackAndEval(dir, 1, "models_real/002_master_chef_can.obj", "detection",
                                  kReal / "data" / "unnamed_can",
                                  "--set tracker.verification.max_penetration=0.02");
  ExpectNoWorseThan(can, {1.844, 2.398, 1.0, 0.967});
  // With the default table check the true pose is refused, as the test's comment says.
  const auto strict = RunMmh("track --quiet --input " + (kReal / "data" / "unnamed_can").string() +
                             " --model " + (kReal / "models_real" / "002_master_chef_can.obj").string() +
                             " --config " + kPreset + " --set track.object=1 --set track.init=\\\"truth\\\" --out " +
                             (dir / "strict").string());
  EXPECT_NE(strict.exit_code, 0);
  EXPECT_THAT(ReadBytes(dir / "strict" / "status.csv"), HasSubstr("into the table"));
}

// The mug (YCB 025: a cylinder with a hollow and a handle, not convex) in the same ten frames,
// with the YCB set's own scan of it (models_real/025_mug.obj, PROVENANCE.md). The foam brick stands
// in front of it, so the predicted mug's window holds the brick too: scored on the whole window the
// true pose explains 27 % of the points (< 0.5) and the track is lost on the first frame; each
// detection then takes a pose turned about the mug's axis (120 deg: the handle is hidden behind
// the mug). tracker.detection.own_segment_share = 0.6 scores a pose on the segments that lie on the
// model. Measured (docs/tracker.md, "The sim-to-real gap"): from the truth's first pose 2.040 deg /
// 0.731 mm, all 10 frames within 5 deg / 5 cm, AR 0.990; from its own detection 4.996 deg /
// 0.866 mm, 5 of 10 within 5 deg / 5 cm, AR 0.942 (the error is a turn about the mug's axis, which
// the hidden handle leaves open: the axis itself is 0.3-2.9 deg off; the 2 deg and 90 %
// are missed). Without the option: 119.7 deg, none of the 10 frames within 5 deg / 5 cm.
TEST(RealRecordingCliTest, TracksTheMugWithItsScannedMesh) {
  TempDir dir;
  const std::string own = "--set tracker.detection.own_segment_share=0.6";
  ExpectNoWorseThan(TrackAndEval(dir, 14, "models_real/025_mug.obj", "truth", kVideo, own),
                    {2.040, 0.731, 1.0, 0.990});
  ExpectNoWorseThan(TrackAndEval(dir, 14, "models_real/025_mug.obj", "detection", kVideo, own),
                    {4.996, 0.866, 0.5, 0.942});
  // The option's reason: without it the truth's pose is not kept (measured 0 of 10 frames within
  // 5 deg / 5 cm; the bound allows one).
  TempDir off;
  const Scores without = TrackAndEval(off, 14, "models_real/025_mug.obj", "truth");
  EXPECT_LE(without.recall_5deg_5cm, kRecallMargin);
}

// The gelatin box with its real shape (the hull of the dataset's points) is found turned over from
// its own detection: its half turns fill the same space and the depth cannot tell them apart.
// tracker.appearance with the YCB scan's colours (models_real/009_gelatin_box_colour.ply,
// PROVENANCE.md) picks, among the poses the depth scores alike, the one whose printed texture
// agrees with the colour image. Measured (docs/tracker.md, "The gelatin box's colours"): from its
// own detection 1.526 deg / 0.877 mm, from the truth's first pose 1.538 deg / 0.891 mm, both with
// all 10 frames within 5 deg / 5 cm and AR 1.000 (the goals met, and the bounds inside
// them); without the option 178.2 deg / 8.05 mm, AR 0.333.
TEST(RealRecordingCliTest, TurnsTheGelatinBoxRightSideUpByItsColours) {
  TempDir dir;
  const std::string colours = "--set track.appearance_model=\\\"" +
                              (kReal / "models_real" / "009_gelatin_box_colour.ply").string() +
                              "\\\" --set tracker.appearance.margin=0.05";
  for (const auto& [init, measured] : {std::pair<std::string, Scores>{"detection", {1.526, 0.877, 1.0, 1.0}},
                                       {"truth", {1.538, 0.891, 1.0, 1.0}}}) {
    SCOPED_TRACE(init);
    ExpectNoWorseThan(TrackAndEval(dir, 8, "models_real/009_gelatin_box.obj", init, kVideo, colours),
                      measured);
  }
  // The option's reason: without it the box is turned over (measured 178.2 deg; a detection on
  // a single frame turns it 176.7-179.4 deg, docs/tracker.md; the bound allows 8 deg less).
  TempDir off;
  EXPECT_GT(TrackAndEval(off, 8, "models_real/009_gelatin_box.obj", "detection").median_rotation_deg,
            170.0);
}

// The header of an ASCII PLY with vertex colours (x y z red green blue) and triangles (12 lines).
std::string ColourPly(int vertices, int faces) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
         "property uchar green\nproperty uchar blue\nelement face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

// A colour model that cannot serve: exit code 2 naming the file and what is wrong with it.
TEST(RealRecordingCliTest, BadAppearanceModelsNameTheFileAndTheValue) {
  TempDir dir;
  const std::string track = "track --input " + kVideo.string() + " --model " +
                            (kReal / "models_real" / "009_gelatin_box.obj").string() +
                            " --config " + kPreset + " --set track.object=8 --set track.max_frames=1 ";
  auto run = [&](const std::string& model, const std::string& out) {
    return RunMmh(track + "--set tracker.appearance.margin=0.05 --set track.appearance_model=\\\"" +
                  model + "\\\" --out " + (dir / out).string());
  };
  // A model without colours (the hull itself).
  const auto plain = run((kReal / "models_real" / "009_gelatin_box.obj").string(), "a");
  EXPECT_EQ(plain.exit_code, 2) << plain.output;
  EXPECT_THAT(plain.output, HasSubstr("009_gelatin_box.obj: the appearance model has no colours"));
  // The option on without a colour model: the tracked model's own colours, which it has not.
  const auto none = RunMmh(track + "--set tracker.appearance.margin=0.05 --out " +
                           (dir / "b").string());
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_THAT(none.output, HasSubstr("no track.appearance_model"));
  // A colour out of its type's range (line 14 of an ASCII PLY: the second vertex).
  WriteText(dir / "bad.ply", ColourPly(3, 1) + "0 0 0 255 0 0\n0.08 0 0 300 0 0\n"
                                             "0 0.09 0.03 0 0 255\n3 0 1 2\n");
  const auto range = run((dir / "bad.ply").string(), "c");
  EXPECT_EQ(range.exit_code, 2) << range.output;
  EXPECT_THAT(range.output, HasSubstr("bad.ply:14: vertex 1"));
  EXPECT_THAT(range.output, HasSubstr("got '300' for property 'red', expected an integer of type uchar"));
  // A colour model in millimetres (the tracked model is in metres).
  WriteText(dir / "mm.ply", ColourPly(4, 2) + "0 0 0 255 0 0\n73 0 0 255 0 0\n"
                                            "0 89 30 255 255 255\n73 89 30 255 255 255\n"
                                            "3 0 1 2\n3 1 3 2\n");
  const auto mm = run((dir / "mm.ply").string(), "d");
  EXPECT_EQ(mm.exit_code, 2) << mm.output;
  EXPECT_THAT(mm.output, HasSubstr("mm.ply: the appearance model is 11"));
  EXPECT_THAT(mm.output, HasSubstr("expected within a factor 1.5 of --model's 0.1"));
}

// The real preset's 3 cm cut would hide the gelatin box (27 mm thin) lying flat: `mmh track` warns
// on stderr and in track_summary.json, naming the option and the thickness; the run goes on.
TEST(RealRecordingCliTest, WarnsWhenTheMinHeightHidesTheModelLyingFlat) {
  TempDir dir;
  const auto track = RunMmh("track --quiet --input " + kVideo.string() + " --model " +
                            (kReal / "models" / "009_gelatin_box.obj").string() + " --config " +
                            kPreset + " --set track.object=8 --set track.max_frames=1 --out " +
                            (dir / "t").string());
  ASSERT_EQ(track.exit_code, 0) << track.output;
  EXPECT_THAT(track.output, HasSubstr("warning: tracker.segmentation.min_height = 0.03 m"));
  EXPECT_THAT(track.output, HasSubstr("0.0269 m thick"));
  const auto summary = nlohmann::json::parse(ReadBytes(dir / "t" / "track_summary.json"));
  ASSERT_EQ(summary["warnings"].size(), 1u);
}

TEST(RealRecordingCliTest, EvalOfTheTruthItselfIsPerfect) {
  TempDir dir;
  // The ground truth as the estimate: every error 0, every recall 1.
  const auto track = RunMmh("track --quiet --input " + kVideo.string() + " --model " +
                            (kReal / "models" / "061_foam_brick.obj").string() + " --config " +
                            kPreset + " --set track.object=21 --set track.init=\\\"truth\\\" --out " +
                            (dir / "t").string());
  ASSERT_EQ(track.exit_code, 0) << track.output;
  const auto result = RunMmh("eval --input " + kVideo.string() + " --model " +
                             (kReal / "models" / "061_foam_brick.obj").string() + " --estimate " +
                             (dir / "t" / "groundtruth.tum").string() +
                             " --set track.object=21 --out " + (dir / "e").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto o = nlohmann::json::parse(ReadBytes(dir / "e" / "eval.json"))["objects"][0];
  EXPECT_EQ(o["ar"], 1.0);
  EXPECT_EQ(o["recall_2deg_2cm"], 1.0);
  EXPECT_THAT(ReadBytes(dir / "e" / "eval_frames.csv"),
              HasSubstr("object,frame,timestamp,has_estimate,rotation_deg"));
}

TEST(RealRecordingCliTest, BadInputsNameTheFileAndTheValue) {
  TempDir dir;
  // A model 1000 times too big (millimetres read as metres).
  const auto big = RunMmh("track --input " + kVideo.string() + " --model " +
                          (kReal / "models" / "061_foam_brick.obj").string() + " --config " +
                          kPreset + " --set track.object=21 --set track.model_scale=1000 --out " +
                          (dir / "a").string());
  EXPECT_EQ(big.exit_code, 2) << big.output;
  EXPECT_THAT(big.output, HasSubstr("061_foam_brick.obj: the model is"));
  EXPECT_THAT(big.output, HasSubstr("track.model_scale=0.001"));
  EXPECT_FALSE(fs::exists(dir / "a"));
  // Several objects and none chosen.
  const auto none = RunMmh("track --input " + kVideo.string() + " --model " +
                           (kReal / "models" / "061_foam_brick.obj").string() + " --out " +
                           (dir / "b").string());
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_THAT(none.output, HasSubstr("8, 14, 21"));
  // A frame whose ground truth has no depth factor.
  TempDir copy;
  fs::copy_file(kVideo / "000001-depth.png", copy / "000001-depth.png");
  WriteText(copy / "000001-meta.txt",
            "intrinsic_matrix: 3 3\n1066 0 0 0 1067 0 313 241 1\ncls_indexes: 1 1\n21\n"
            "poses: 3 4 1\n1 0 0 0 1 0 0 0 1 0 0 0.6\n");
  const auto scale = RunMmh("track --input " + copy.path().string() + " --model " +
                            (kReal / "models" / "061_foam_brick.obj").string() + " --out " +
                            (dir / "c").string());
  EXPECT_EQ(scale.exit_code, 2) << scale.output;
  EXPECT_THAT(scale.output, HasSubstr("000001-meta.txt: variable 'factor_depth' is missing"));
}

}  // namespace
}  // namespace mmh

namespace mmh {
namespace {

// A TUM-layout folder (camera.json, groundtruth.txt) is evaluated the same way: a rendered take's
// own ground truth as the estimate scores perfectly.
TEST(RealRecordingCliTest, EvalOfATumFolderWithCameraJson) {
  TempDir dir;
  const fs::path take = dir / "take";
  const auto render = RunMmh("render --quiet --out " + take.string() + " --set render.frames=4");
  ASSERT_EQ(render.exit_code, 0) << render.output;
  const auto result = RunMmh("eval --quiet --input " + take.string() + " --model " +
                             (take / "model.ply").string() + " --estimate " +
                             (take / "groundtruth.txt").string() + " --out " + (dir / "e").string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto o = nlohmann::json::parse(ReadBytes(dir / "e" / "eval.json"))["objects"][0];
  EXPECT_EQ(o["frames"], 4);
  EXPECT_EQ(o["ar"], 1.0);
  EXPECT_EQ(o["median_translation_mm"], 0.0);
}

}  // namespace
}  // namespace mmh
