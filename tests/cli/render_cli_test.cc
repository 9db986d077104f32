// End-to-end tests of `mmh render` and `mmh sensor-check` as a user runs them: the outputs a
// tracker needs, identical bytes on a rerun, exit code 2 and no output on bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

using test_util::ReadBytes;
using test_util::RunMmh;

class RenderCliTest : public ::testing::Test {
 protected:
  test_util::TempDir temp_;
  const fs::path dir_ = temp_.path();
};

TEST_F(RenderCliTest, WritesAReadableTumRgbdFolderWithGroundTruthAndIsReproducible) {
  const std::string args =
      " --set render.frames=4 --set scene.props=castle --set render.bop=true "
      "--set render.fakenect=true --quiet";
  const auto first = RunMmh("render --out " + (dir_ / "a").string() + args);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto second = RunMmh("render --threads 1 --out " + (dir_ / "b").string() + args);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  for (const char* file :
       {"camera.json", "groundtruth.txt", "model.ply", "slider.csv", "scene.json",
        "config.resolved.json", "run.json", "rgb.txt", "depth.txt", "bop/scene_gt.json",
        "bop/scene_camera.json", "bop/models/obj_000001.ply", "bop/depth/000003.png",
        "bop/rgb/000003.png"}) {
    EXPECT_TRUE(fs::exists(dir_ / "a" / file)) << file;
  }
  EXPECT_TRUE(fs::exists(dir_ / "a.fakenect" / "INDEX.txt"));
  RgbdFolderReader a(dir_ / "a");
  RgbdFolderReader b(dir_ / "b");
  ASSERT_EQ(a.size(), 4);
  for (int i = 0; i < 4; ++i) {
    const RgbdFrame fa = a.Read(i);
    const RgbdFrame fb = b.Read(i);
    EXPECT_EQ(fa.depth, fb.depth) << "frame " << i << " differs with --threads 1";
    EXPECT_EQ(fa.rgb, fb.rgb);
    EXPECT_GT(std::count_if(fa.depth.begin(), fa.depth.end(), [](uint16_t d) { return d > 0; }),
              200000);
  }
  EXPECT_EQ(ReadBytes(dir_ / "a" / "groundtruth.txt"), ReadBytes(dir_ / "b" / "groundtruth.txt"));
  EXPECT_EQ(ReadTum(dir_ / "a" / "groundtruth.txt").size(), 4u);
}

// render.bop writes a whole BOP scene (scene_gt.json, scene_camera.json, depth/ and rgb/ by image
// id): the BOP reader of `mmh track` and `mmh eval` take it as it is, and the tracker started at
// the truth follows the rendered Soldier within its accuracy on simulated frames (docs/tracker.md,
// "Accuracy": medians below 1 deg and 1 mm).
TEST_F(RenderCliTest, ItsBopSceneIsReadByTrackAndEval) {
  const fs::path render = dir_ / "render";
  // (Structured-light frames, the default, measured: median 1.85 deg and 1.73 mm, 7 of 10 frames
  // within 5 deg and 5 cm.)
  const auto rendered = RunMmh("render --quiet --set render.frames=10 --set render.bop=true" +
                               test_util::StatisticalFramesFlags() + " --out " +
                               render.string());
  ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
  EXPECT_EQ(ReadBytes(render / "bop" / "depth" / "000009.png"),
            ReadBytes(render / "depth" / "0.300000.png"));
  EXPECT_FALSE(fs::exists(render / "bop" / "depth" / "000010.png"));
  const auto track = RunMmh("track --quiet --input " + (render / "bop").string() + " --model " +
                            (render / "model.ply").string() +
                            " --set track.init=\\\"truth\\\" --out " + (dir_ / "track").string());
  ASSERT_EQ(track.exit_code, 0) << track.output;
  const auto eval = RunMmh("eval --quiet --input " + (render / "bop").string() + " --model " +
                           (render / "model.ply").string() + " --estimate " +
                           (dir_ / "track" / "trajectory.tum").string() + " --out " +
                           (dir_ / "eval").string());
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  const nlohmann::json overall =
      nlohmann::json::parse(ReadBytes(dir_ / "eval" / "eval.json"))["overall"];
  EXPECT_EQ(overall["frames"], 10);
  EXPECT_LT(overall["median_rotation_deg"].get<double>(), 1.0);
  EXPECT_LT(overall["median_translation_mm"].get<double>(), 1.0);
  EXPECT_EQ(overall["recall_5deg_5cm"], 1.0);
}

TEST_F(RenderCliTest, BadInputExitsWithTwoNamingTheKeyAndWritesNothing) {
  const fs::path out = dir_ / "out";
  auto r = RunMmh("render --out " + out.string() + " --set sensor.intrinsics.fx=-1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("sensor.intrinsics.fx"));
  r = RunMmh("render --out " + out.string() + " --set sensor.noize=true");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.output, HasSubstr("noize"));
  EXPECT_THAT(r.output, HasSubstr("noise"));  // did you mean
  std::ofstream(dir_ / "proxy.json")
      << R"({"bricks": [{"type": "2x5", "at": [0, 0, 0], "color": "red"}]})";
  r = RunMmh("render --out " + out.string() + " --set render.proxy=\\\"" +
             (dir_ / "proxy.json").string() + "\\\"");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("2x5"));
  std::ofstream(dir_ / "broken.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
  r = RunMmh("render --out " + out.string() + " --set render.proxy=\\\"" +
             (dir_ / "broken.obj").string() + "\\\"");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("broken.obj"));
  EXPECT_FALSE(fs::exists(out));
  r = RunMmh("render --out /proc/mmh_cannot_write_here --set render.frames=1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST_F(RenderCliTest, RendersAParticipantsTakeAndItsAnnotationSession) {
  const std::string study = std::string(MMH_SOURCE_DIR) + "/configs/study_soldier.json";
  const std::string story = std::string(MMH_SOURCE_DIR) + "/configs/stories/soldier.json";
  const std::string args =
      " --config " + study + " --set scenario.story=\\\"" + story +
      "\\\" --set scenario.animator=2 --set render.take=1 --set render.frames=3 --quiet";
  auto r = RunMmh("render --out " + (dir_ / "rec").string() + args);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunMmh("render --out " + (dir_ / "ann").string() + args + " --set render.session=annotation");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* file : {"take.tum", "take.csv", "flaws.csv", "participant.json"}) {
    EXPECT_TRUE(fs::exists(dir_ / "rec" / file)) << file;
  }
  // The same participant's same take in both sessions; the whole take is described even when
  // only its first frames are rendered.
  EXPECT_EQ(ReadBytes(dir_ / "rec" / "take.tum"), ReadBytes(dir_ / "ann" / "take.tum"));
  EXPECT_GT(ReadTum(dir_ / "rec" / "take.tum").size(), 1500u);
  EXPECT_EQ(ReadTum(dir_ / "rec" / "groundtruth.txt").size(), 3u);
  // The rendered slider is the annotator's hand, as take.csv reports it.
  std::istringstream take(ReadBytes(dir_ / "ann" / "take.csv"));
  std::string header, row;
  std::getline(take, header);
  EXPECT_THAT(header, HasSubstr(",judgement,delay,slider"));
  std::istringstream slider(ReadBytes(dir_ / "ann" / "slider.csv"));
  std::string slider_row;
  std::getline(slider, slider_row);
  for (int i = 0; i < 3; ++i) {
    std::getline(take, row);
    std::getline(slider, slider_row);
    const double from_take = std::stod(row.substr(row.rfind(',') + 1));
    const double rendered = std::stod(slider_row.substr(slider_row.find(',') + 1));
    EXPECT_NEAR(from_take, rendered, 1e-9) << i;
  }
  // A broken story names its file and beat; nothing is written.
  test_util::WriteText(
      dir_ / "bad.json",
      R"({"name": "b", "objects": [{"name": "a", "path": [[0, 0], [0.1, 0]], "end": 5,
                           "beats": [{"kind": "walk", "start": 0, "to": 1}, {"kind": "skip", "start": 2}]}]})");
  r = RunMmh("render --out " + (dir_ / "bad").string() + " --set scenario.story=\\\"" +
             (dir_ / "bad.json").string() + "\\\" --quiet");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, HasSubstr("bad.json: objects[0].beats[1].kind"));
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

TEST_F(RenderCliTest, SensorCheckPrintsRealAndRenderedColumns) {
  if (!fs::exists(fs::path(MMH_SOURCE_DIR) / "../shared/data/real-rgbd/TUM_depth.png") &&
      !fs::exists("/work/shared/data/real-rgbd/TUM_depth.png")) {
    GTEST_SKIP() << "real frames absent";
  }
  const auto r = RunMmh("sensor-check --frames 1 --out " + dir_.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* column : {"TUM real", "NYU real", "SUN real", "rendered stat.", "rendered SL",
                             "missing, shadow [%]", "correlation length [px]", "goal"}) {
    EXPECT_THAT(r.output, HasSubstr(column));
  }
  EXPECT_TRUE(fs::exists(dir_ / "sensor_check.json"));
  EXPECT_TRUE(fs::exists(dir_ / "sensor_check.png"));
  // Like for like (docs/sensor.md): YCB-Video's first frame and the same view rendered in both
  // modes, each with the object found and runs beside it; the real frame's bands scaled to the
  // rendered sensor's pixels (its focal length 1066.8 px against 525).
  EXPECT_THAT(r.output, HasSubstr("like for like: around the object"));
  // ... and away from the other labelled objects (the mug and the foam brick beside the box).
  EXPECT_THAT(r.output, HasSubstr("like for like, away from the other objects"));
  EXPECT_TRUE(fs::exists(dir_ / "sensor_check_view.png"));
  // The same on the rendered sensor's grid: the real 640 x 480 view at 1066.8 px is 315 x 236
  // pixels at 525 px, each shown as 2 x 2, three panels 8 px apart.
  const std::string png = ReadBytes(dir_ / "sensor_check_view_native.png");
  ASSERT_GT(png.size(), 24u);
  auto big_endian = [&](size_t at) {
    uint32_t value = 0;
    for (size_t i = at; i < at + 4; ++i) value = value << 8 | static_cast<uint8_t>(png[i]);
    return value;
  };
  EXPECT_EQ(big_endian(16), 3u * 630 + 2 * 8);
  EXPECT_EQ(big_endian(20), 472u);
  const nlohmann::json like =
      nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"))["like_for_like"];
  ASSERT_EQ(like.size(), 3u);
  const nlohmann::json away =
      nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"))["like_for_like_away"];
  ASSERT_EQ(away.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(away[k]["pixels"].get<double>(), like[k]["pixels"].get<double>()) << away[k].dump();
    EXPECT_GT(away[k]["pixels"].get<double>(), 0.5 * like[k]["pixels"].get<double>());
  }
  EXPECT_NEAR(like[0]["pixel_scale"].get<double>(), 525.0 / 1066.778, 1e-3);
  for (const auto& row : like) {
    EXPECT_GT(row["pixels"].get<double>(), 1000) << row.dump();
    EXPECT_GT(row["missing_share"].get<double>(), 0.01) << row.dump();
    EXPECT_GT(row["edge_runs"].get<int>(), 10) << row.dump();
    EXPECT_GT(row["shadow_runs"].get<int>(), 10) << row.dump();
    // Widths across the bands (BandWidthsAcross): at least a pixel, at most the neighbourhood.
    for (const char* key : {"shadow_band_across_px", "edge_band_across_px"}) {
      EXPECT_GE(row[key].get<double>(), 1.0) << key << " " << row.dump();
      EXPECT_LE(row[key].get<double>(), 21.0) << key << " " << row.dump();
    }
  }
  EXPECT_THAT(r.output, HasSubstr("edge band across [px]"));
  // The object's silhouette (sim/silhouette_bleed.h), measured at both sides of the gelatin box in
  // every frame. The statistical sensor's shadow is the geometric one, so nothing of the box
  // bleeds into it; the real frame's box bleeds onto the table on both sides (measured 0.36 and
  // 0.82 px) and loses less than a pixel of its outline.
  for (const auto& row : like) {
    EXPECT_GT(row["shadow_side_ends"].get<int>(), 30) << row.dump();
    EXPECT_GT(row["edge_side_ends"].get<int>(), 30) << row.dump();
    for (const char* key : {"shadow_side_bleed_px", "edge_side_bleed_px", "shadow_side_erosion_px",
                            "edge_side_erosion_px"}) {
      EXPECT_GE(row[key].get<double>(), 0.0) << key << " " << row.dump();
      EXPECT_LT(row[key].get<double>(), 3.0) << key << " " << row.dump();
    }
  }
  EXPECT_EQ(like[1]["shadow_side_bleed_px"].get<double>(), 0.0);
  EXPECT_GT(like[0]["shadow_side_bleed_px"].get<double>(), 0.1);
  EXPECT_GT(like[0]["edge_side_bleed_px"].get<double>(), 0.1);
  EXPECT_THAT(r.output, HasSubstr("bleed, shadow side [px]"));
  // Matched on the IR camera's grid and registered (match_on_ir_grid, the default), over the 8
  // patterns: the registration carries the box's outline over the wall beside it on the edge
  // side, which the delivered-grid shortcut (the other grid's column) does not (measured 0.65 px
  // against 0.01; real 0.76).
  const nlohmann::json checked = nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"));
  EXPECT_EQ(checked["other_grid"], "delivered");
  const nlohmann::json& ir_grid = checked["like_for_like_patterns"]["patterns"];
  const nlohmann::json& shortcut = checked["like_for_like_other_grid_patterns"]["patterns"];
  ASSERT_EQ(ir_grid.size(), 8u);
  ASSERT_EQ(shortcut.size(), 8u);
  double ir_bleed = 0, shortcut_bleed = 0;
  for (size_t k = 0; k < 8; ++k) {
    ir_bleed += ir_grid[k]["edge_side_bleed_px"].get<double>() / 8;
    shortcut_bleed += shortcut[k]["edge_side_bleed_px"].get<double>() / 8;
  }
  EXPECT_GT(ir_bleed, 0.3);
  EXPECT_LT(shortcut_bleed, 0.1);
  EXPECT_GT(checked["like_for_like_real_frames"]["ratio_of_means"]["missing_share"].get<double>(),
            0.8);
  EXPECT_GT(checked["like_for_like_other_grid_real_frames"]["ratio_of_means"]["missing_share"]
                .get<double>(),
            0.8);
  // Along the desk's edge (the committed view's desk, fitted from the real frame): the real frame
  // and both modes see the floor beyond it, the IR shadow falls on it (runs of the shadow class in
  // every row that crosses the edge, about 120) and the rendered edge lies where the real one is
  // (the real band's width across within a factor 1.6 of structured light's; measured 8.6 and
  // 11.9 px).
  const nlohmann::json desk =
      nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"))["like_for_like_desk_edge"];
  ASSERT_EQ(desk.size(), 3u);
  for (const auto& row : desk) {
    EXPECT_GT(row["pixels"].get<double>(), 1000) << row.dump();
    EXPECT_GT(row["shadow_runs"].get<int>(), 80) << row.dump();
    EXPECT_GT(row["missing_share"].get<double>(), 0.1) << row.dump();
  }
  EXPECT_GT(desk[0]["shadow_band_across_px"].get<double>(),
            desk[2]["shadow_band_across_px"].get<double>() / 1.6);
  EXPECT_LT(desk[0]["shadow_band_across_px"].get<double>(),
            desk[2]["shadow_band_across_px"].get<double>() * 1.6);
  EXPECT_THAT(r.output, HasSubstr("along the desk's edge"));
  // The anchors issue 23 names (sim/anchor_noise.h), on the demo frame against TUM and on the view
  // against the real frames: structured light is nearer the real frames than either on the
  // missing share near the object (measured: structured light 1.10 of the real frames' mean,
  // ICL-NUIM 0.00 (no holes but the image border's), simkinect 2.17 (its filter fails windows
  // wherever the disparity varies)).
  EXPECT_THAT(r.output, HasSubstr("the anchors (sim/anchor_noise.h)"));
  const nlohmann::json all = nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"));
  EXPECT_TRUE(all["error_structure"].contains("anchor ICL-NUIM"));
  EXPECT_TRUE(all["error_structure"].contains("anchor simkinect"));
  const nlohmann::json& anchors = all["like_for_like_anchors"];
  ASSERT_EQ(anchors.size(), 2u);
  const double structured_missing =
      all["like_for_like_real_frames"]["ratio_of_means"]["missing_share"].get<double>();
  for (const nlohmann::json& anchor : anchors) {
    ASSERT_EQ(anchor["near"].size(), 8u) << anchor["model"];
    ASSERT_EQ(anchor["desk_edge"].size(), 8u) << anchor["model"];
    const double missing = anchor["near_ratio_of_means"]["missing_share"].get<double>();
    EXPECT_LT(std::abs(structured_missing - 1), std::abs(missing - 1)) << anchor["model"];
  }
  // The statistical sensor's holes are rules; the structured light's beside the object come from
  // the matching and so are more (measured 8.5 and 10.3 %, real 12.3 %).
  EXPECT_GT(like[2]["missing_share"].get<double>(), like[1]["missing_share"].get<double>());

  // Over speckle patterns (--patterns, 8 by default): the config's pattern_seed and the next
  // seven; the first pattern is the table's structured-light column, and the spread is of the
  // per-pattern ratios to the real frame (recomputed here).
  EXPECT_THAT(r.output, HasSubstr("8 patterns: SL/real"));
  const nlohmann::json json = nlohmann::json::parse(ReadBytes(dir_ / "sensor_check.json"));
  for (const char* table : {"like_for_like", "like_for_like_away", "like_for_like_desk_edge"}) {
    const nlohmann::json& over = json[std::string(table) + "_patterns"];
    ASSERT_EQ(over["patterns"].size(), 8u) << table;
    const nlohmann::json& real = json[table][0];
    // Along the desk's edge some patterns leave no edge run (the band's width is then NaN, left
    // out of the spread): its edge band is not recomputed here.
    const bool desk_edge = std::string(table) == "like_for_like_desk_edge";
    for (const char* key : {"missing_share", "shadow_band_across_px", "edge_band_across_px"}) {
      if (desk_edge && std::string(key) == "edge_band_across_px") continue;
      EXPECT_EQ(over["patterns"][0][key], json[table][2][key]) << table << " " << key;
      double sum = 0, sum2 = 0, low = 1e9;
      for (int k = 0; k < 8; ++k) {
        EXPECT_EQ(over["patterns"][k]["pattern_seed"].get<uint64_t>(), 20100604u + k);
        const double ratio = over["patterns"][k][key].get<double>() / real[key].get<double>();
        sum += ratio;
        sum2 += ratio * ratio;
        low = std::min(low, ratio);
      }
      const nlohmann::json& spread = over["ratio_to_real"][key];
      EXPECT_NEAR(spread["mean"].get<double>(), sum / 8, 1e-12) << table << " " << key;
      EXPECT_NEAR(spread["sd"].get<double>(), std::sqrt((sum2 - sum * sum / 8) / 7), 1e-9);
      EXPECT_NEAR(spread["min"].get<double>(), low, 1e-12);
      EXPECT_GT(spread["sd"].get<double>(), 0.0) << "the patterns differ";
    }
  }
  // The step law (sim/step_law.h): the statistical sensor's shadows and occlusions are the
  // geometry's, so its fit recovers the rendered sensor's own distances (projector 5 cm, IR camera
  // 2.5 cm from the colour camera: measured 5.00 and 2.52 on the demo walk, 4.95 on the view,
  // whose edge side has few large steps); every row pools its frames.
  EXPECT_THAT(r.output, HasSubstr("step law of the missing runs beside depth steps"));
  EXPECT_THAT(r.output, HasSubstr("small steps only"));
  const nlohmann::json& laws = json["step_laws"];
  ASSERT_EQ(laws.size(), 5u);
  EXPECT_EQ(laws[0]["frames"], "TUM real");
  EXPECT_NEAR(laws[1]["fx_px"].get<double>(), 582.62, 0.01);  // NYU's IR camera
  // --kinect-sequence: TUM's freiburg1_xyz, its two committed frames at fr1's focal length.
  EXPECT_EQ(laws[2]["frames"], "real TUM rgbd_dataset_freiburg1_xyz");
  EXPECT_EQ(laws[2]["frame_count"].get<int>(), 2);
  EXPECT_EQ(laws[2]["fx_px"].get<double>(), 517.3);
  EXPECT_GT(laws[2]["shadow"]["runs"].get<int>(), 500);
  // ... and its first frame's error structure beside TUM's and NYU's, at fr1's intrinsics.
  const nlohmann::json& fr1 = json["error_structure"]["real TUM rgbd_dataset_freiburg1_xyz"];
  EXPECT_GT(fr1["patches"].get<int>(), 100) << fr1.dump();
  EXPECT_THAT(r.output, HasSubstr("real TUM rgbd_dataset_freiburg1_xyz"));
  const nlohmann::json& statistical = laws[3];
  ASSERT_EQ(statistical["frames"], "rendered stat.");
  EXPECT_NEAR(statistical["shadow_geometry_m"].get<double>(), 0.05, 1e-12);
  EXPECT_NEAR(statistical["edge_geometry_m"].get<double>(), 0.025, 1e-12);
  for (const char* side : {"shadow", "edge"}) {
    const nlohmann::json& law = statistical[side];
    const double geometry = statistical[std::string(side) + "_geometry_m"].get<double>();
    EXPECT_GT(law["runs"].get<int>(), 100) << law.dump();
    EXPECT_NEAR(law["slope_m"].get<double>(), geometry, 0.1 * geometry) << side;
    EXPECT_LT(law["slope_low_m"].get<double>(), geometry) << side;
    EXPECT_GT(law["slope_high_m"].get<double>(), geometry) << side;
    EXPECT_NEAR(law["intercept_px"].get<double>(), 0.0, 1.0) << side;
  }
  // Small steps alone (up to 200 px / m at 525 px): the demo walk has few others.
  const nlohmann::json& small = statistical["shadow_small_steps"];
  EXPECT_GT(small["runs"].get<int>(), 100) << small.dump();
  EXPECT_LE(small["step_p90_px_per_m"].get<double>(), 200.0);
  EXPECT_NEAR(small["slope_m"].get<double>(), 0.05, 0.005) << small.dump();
  const nlohmann::json& view_laws = json["view_step_laws"];
  ASSERT_EQ(view_laws.size(), 3u);
  EXPECT_EQ(view_laws[0]["frame_count"].get<int>(), 10);
  EXPECT_EQ(view_laws[2]["frame_count"].get<int>(), 8);
  EXPECT_NEAR(view_laws[1]["shadow"]["slope_m"].get<double>(), 0.05, 0.005);
  for (const auto& row : view_laws) {
    // The desk's edge gives the view's shadows steps up to ~650 px / m (1 / 0.55 - 1 / 1.4 m at
    // 525 px; at 1066.8 px in the real frames): the slope is well determined in every row.
    EXPECT_GT(row["shadow"]["step_p90_px_per_m"].get<double>(),
              500 * row["fx_px"].get<double>() / 525);
    EXPECT_LT(
        row["shadow"]["slope_high_m"].get<double>() - row["shadow"]["slope_low_m"].get<double>(),
        0.005)
        << row.dump();
  }

  // Over the real recording's frames 1-10 (by default as many as it has, up to 10): each frame's
  // statistics, and the ratio of the patterns' mean to the frames' mean (recomputed here).
  EXPECT_THAT(r.output, HasSubstr("over real frames 1-10 and 8 patterns"));
  for (const char* table : {"like_for_like", "like_for_like_away", "like_for_like_desk_edge"}) {
    const nlohmann::json& frames = json[std::string(table) + "_real_frames"];
    ASSERT_EQ(frames["frames"].size(), 10u) << table;
    EXPECT_EQ(frames["frames"][0]["missing_share"], json[table][0]["missing_share"]);
    EXPECT_THAT(frames["frames"][9]["frame"].get<std::string>(), HasSubstr("frame 10"));
    double real = 0, rendered = 0;
    for (int k = 0; k < 10; ++k) real += frames["frames"][k]["missing_share"].get<double>() / 10;
    for (int k = 0; k < 8; ++k) {
      rendered +=
          json[std::string(table) + "_patterns"]["patterns"][k]["missing_share"].get<double>() / 8;
    }
    EXPECT_NEAR(frames["ratio_of_means"]["missing_share"].get<double>(), rendered / real, 1e-12);
    // The real frames differ (the camera moves by millimetres), so the spread is not zero.
    EXPECT_NE(frames["frames"][0]["missing_share"], frames["frames"][5]["missing_share"]);
  }
  // The view over time in structured light: from a still camera only the IR noise changes; moved
  // as the real camera moved, the pattern slides over the scene and the errors persist less at
  // lag 4 (measured 0.464 and 0.431 with slanted windows to first order, the default since
  // 2026-12-02, whose slopes no longer leave a fixed error; 0.648 and 0.636 with them off, where
  // the floor beyond the desk, whose windows at 1.4 m are mostly IR noise, new in every frame,
  // thins the difference: 0.818 and 0.756 without it). On
  // the IR camera's grid (the default) the registered frame's border loses the desk and the floor:
  // 422-510 planar windows a lag, against about 1 800 on the delivered grid.
  // Then the anchors from a still camera: ICL-NUIM's noise is new in every frame but for the raw
  // lattice (measured rho 0.08 / 0.09), simkinect keeps its fixed dot filter and its centimetre
  // terraces (0.54 / 0.58).
  // First the real view's own frames: the real sequence's row again, at lags 1, 2 and 4.
  // Following the surface (frame k's depth where the point seen at each pixel moved with the
  // camera) the real and the moved rows persist less at lag 4 than at the same pixels (measured
  // real 0.089 against 0.243, the model 0.148 against 0.610): in the device as in the model the
  // persistent error stays with the pixel (the projected pattern), not with the surface.
  const nlohmann::json& view_temporal = json["view_temporal_correlation"];
  ASSERT_EQ(view_temporal.size(), 5u);
  const nlohmann::json& real_temporal = json["temporal_correlation"][0];
  ASSERT_THAT(real_temporal["sequence"].get<std::string>(), HasSubstr("real YCB-Video"));
  ASSERT_EQ(real_temporal["lags"].size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(view_temporal[0]["lags"][k]["rho"], real_temporal["lags"][k]["rho"]);
  }
  EXPECT_EQ(view_temporal[0]["lags"][2]["lag_frames"].get<int>(), 4);
  EXPECT_EQ(view_temporal[3]["sequence"], "view, ICL-NUIM, still");
  EXPECT_LT(view_temporal[3]["lags"][0]["rho"].get<double>(), 0.2);
  for (const auto& row : view_temporal) {
    for (const auto& lag : row["lags"]) EXPECT_GT(lag["windows"].get<int>(), 300) << row.dump();
  }
  EXPECT_GT(view_temporal[1]["lags"][2]["rho"].get<double>(), 0.4);
  EXPECT_LT(view_temporal[2]["lags"][2]["rho"].get<double>(),
            view_temporal[1]["lags"][2]["rho"].get<double>() - 0.008);
  EXPECT_FALSE(view_temporal[1]["lags"][2].contains("following_the_surface"));
  for (const int row : {0, 2}) {
    const nlohmann::json& lag4 = view_temporal[row]["lags"][2];
    EXPECT_GT(lag4["following_the_surface"]["windows"].get<int>(), 300) << lag4.dump();
    EXPECT_LT(lag4["following_the_surface"]["rho"].get<double>(), lag4["rho"].get<double>() - 0.1)
        << lag4.dump();
  }

  // The view's small planar patches like for like, every frame on the rendered sensor's pixel grid
  // over the real camera's field of view: the real frames 1-10, the statistical view, structured
  // light over the 8 patterns, the anchors over 8 noise seeds. The statistical sensor draws each
  // pixel's noise from the per-pixel model the noise is divided by, so on planes its small-patch
  // noise is the model's and its residuals are not correlated; the real device's are, and so are
  // structured light's (block matching).
  const nlohmann::json& patches = json["like_for_like_small_patches"];
  ASSERT_EQ(patches.size(), 5u);
  EXPECT_EQ(patches[0]["draws"].size(), 10u);
  EXPECT_EQ(patches[1]["source"], "view, stat.");
  EXPECT_EQ(patches[1]["draws"].size(), 1u);
  EXPECT_EQ(patches[2]["draws"].size(), 8u);
  EXPECT_EQ(patches[3]["source"], "view, ICL-NUIM");
  EXPECT_EQ(patches[4]["draws"].size(), 8u);
  for (const auto& row : patches) {
    // (simkinect's centimetre terraces leave about 170 planar windows, the others 450-600.)
    for (const auto& draw : row["draws"])
      EXPECT_GT(draw["patches"].get<int>(), 100) << row["source"];
    const double real_noise = patches[0]["mean"]["noise_over_model"].get<double>();
    EXPECT_NEAR(row["ratio_of_means"]["noise_over_model"].get<double>(),
                row["mean"]["noise_over_model"].get<double>() / real_noise, 1e-12);
  }
  EXPECT_NEAR(patches[1]["mean"]["noise_over_model"].get<double>(), 1.0, 0.15);
  EXPECT_LT(std::abs(patches[1]["mean"]["autocorrelation_lag_1"].get<double>()), 0.1);
  EXPECT_GT(patches[0]["mean"]["autocorrelation_lag_1"].get<double>(), 0.3);
  EXPECT_GT(patches[2]["mean"]["autocorrelation_lag_1"].get<double>(), 0.3);
  EXPECT_THAT(r.output, HasSubstr("like for like, the view's small planar patches"));

  // The second committed view: the foam brick with the box and the mug beside it.
  const fs::path ycbv = fs::path(MMH_SOURCE_DIR) / "tests/data/real/ycbv";
  const auto brick = RunMmh(
      "sensor-check --frames 1 --patterns 2 --view-frames 2 --view-object 21 --view " +
      (ycbv / "views/061_foam_brick_static.json").string() + " --view-model " +
      (ycbv / "models_real/061_foam_brick.obj").string() + " --out " + (dir_ / "brick").string());
  ASSERT_EQ(brick.exit_code, 0) << brick.output;
  const nlohmann::json brick_json =
      nlohmann::json::parse(ReadBytes(dir_ / "brick" / "sensor_check.json"));
  for (const auto& row : brick_json["like_for_like"]) {
    EXPECT_GT(row["pixels"].get<double>(), 1000) << row.dump();
  }
  EXPECT_EQ(brick_json["like_for_like_real_frames"]["frames"].size(), 2u);
  // Inside the objects, clear of their outlines (the mask shrunk by 5 px): the real gelatin box's
  // printed face keeps its depth (0.35 % missing in frame 1) as the rendered one does (0.07 %),
  // while the real foam brick's face has streaks of missing pixels (4.4 %) that the model does
  // not make (0.2 %: the foam's scattering is not modelled; docs/sensor.md, "Inside the objects").
  const nlohmann::json& box_rows = json["like_for_like"];
  const nlohmann::json& brick_rows = brick_json["like_for_like"];
  ASSERT_EQ(box_rows.size(), 3u);
  ASSERT_EQ(brick_rows.size(), 3u);
  for (const auto* rows : {&box_rows, &brick_rows}) {
    for (const auto& row : *rows)
      EXPECT_GT(row["interior_pixels"].get<double>(), 500) << row.dump();
  }
  EXPECT_LT(box_rows[0]["interior_missing_share"].get<double>(), 0.01);
  EXPECT_LT(box_rows[2]["interior_missing_share"].get<double>(), 0.01);
  EXPECT_GT(brick_rows[0]["interior_missing_share"].get<double>(), 0.02);
  EXPECT_LT(brick_rows[2]["interior_missing_share"].get<double>(), 0.01);

  // One pattern: no spread; a count out of range is a usage error that writes nothing.
  const auto one = RunMmh("sensor-check --frames 1 --patterns 1");
  ASSERT_EQ(one.exit_code, 0) << one.output;
  EXPECT_THAT(one.output, Not(HasSubstr("patterns: SL/real")));
  const auto zero =
      RunMmh("sensor-check --frames 1 --patterns 0 --out " + (dir_ / "zero").string());
  EXPECT_EQ(zero.exit_code, 2) << zero.output;
  EXPECT_THAT(zero.output, HasSubstr("--patterns"));
  EXPECT_FALSE(fs::exists(dir_ / "zero"));
}

}  // namespace
}  // namespace mmh
