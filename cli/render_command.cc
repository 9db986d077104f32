#include "cli/render_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/image_io.h"
#include "sim/error_structure.h"
#include "sim/render_session.h"
#include "sim/sensor_check.h"

namespace mmh::cli {
namespace {

void RunRender(const CommonFlags& common, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(common);
  const sim::RenderConfig render = sim::RenderConfig::FromConfig(config);
  const auto threads = LimitThreads(common.threads);
  const bool bar = ShowProgress(common);
  const std::filesystem::path out = common.out_dir;
  const nlohmann::json resolved = render.ToJson();
  nlohmann::json timings;
  const auto progress = [&](int done, int total) {
    if (bar && (done % 10 == 0 || done == total)) {
      std::cerr << "\rrender: " << done << " / " << total << " frames" << std::flush;
      if (done == total) std::cerr << '\n';
    }
  };
  // The run's own files go into the staging folder too: the folder appears whole or not at all.
  const auto add_run_files = [&](const std::filesystem::path& staging,
                                 const sim::RenderSummary& summary) {
    timings = summary.ToJson();
    WriteFileAtomically(staging / "render_summary.json", timings.dump(2) + "\n");
    WriteFileAtomically(staging / "config.resolved.json", resolved.dump(2) + "\n");
    WriteFileAtomically(staging / "run.json",
                        Provenance(argv, resolved, common.threads, timings).dump(2) + "\n");
  };
  const sim::RenderSummary summary = sim::RenderSequence(render, out, progress, add_run_files);
  if (!common.quiet) {
    std::cout << "render: " << summary.frames << " frames in " << summary.seconds << " s ("
              << timings["frames_per_second"].get<double>() << " frames/s rendering; writing "
              << summary.write_seconds << " s), " << 100 * summary.missing_fraction
              << " % depth missing\n"
              << "written: " << out.string()
              << "/{rgb/, depth/, rgb.txt, depth.txt, groundtruth.txt, camera.json, model.ply, "
                 "slider.csv, scene.json, render_summary.json, config.resolved.json, run.json"
              << (render.render.story.empty() ? ""
                                              : ", take.tum, take.csv, flaws.csv, participant.json")
              << (render.render.bop ? ", bop/" : "") << "}"
              << (render.render.fakenect ? " and " + out.string() + ".fakenect/" : "") << "\n";
  }
}

struct SensorCheckArgs {
  CommonFlags common;
  std::string data;
  int frames = 3;
};

void RunSensorCheck(const SensorCheckArgs& args, const std::vector<std::string>& argv) {
  const std::filesystem::path data = args.data;
  std::vector<sim::SensorStatistics> columns;
  sim::SensorCheckOptions options;
  // Real frames: TUM (5000 units per metre), NYU raw disparity, SUN (millimetres).
  const auto tum = ReadDepthPng16(data / "TUM_depth.png");
  columns.push_back(sim::ComputeSensorStatistics("TUM real",
                                                 sim::DepthMetresFromUnits(tum.values, 1.0 / 5000),
                                                 tum.width, tum.height, options));
  const auto nyu = ReadNyuRawDisparity(data / "NYU_depth.pgm");
  columns.push_back(sim::ComputeSensorStatistics("NYU real", sim::DepthMetresFromNyuRaw(nyu.values),
                                                 nyu.width, nyu.height, options, &nyu.values));
  const auto sun = ReadSunDepth(data / "SUN_depth.png");
  columns.push_back(sim::ComputeSensorStatistics(
      "SUN real", sim::DepthMetresFromUnits(sun.values, 0.001), sun.width, sun.height, options));
  // The error structure of the Kinect v1 frames (SUN's sensor differs) beside the rendered ones.
  const std::vector<float> tum_m = sim::DepthMetresFromUnits(tum.values, 1.0 / 5000);
  std::vector<std::string> structure_names{"TUM real", "NYU real"};
  std::vector<sim::ErrorStructure> structures{
      sim::AnalyseErrorStructure(tum_m, tum.width, tum.height, options.intrinsics,
                                 options.calibration, options.noise),
      sim::AnalyseErrorStructure(sim::DepthMetresFromNyuRaw(nyu.values), nyu.width, nyu.height,
                                 options.intrinsics, options.calibration, options.noise)};

  // Rendered frames of the table-top scene with the castle, from the config (defaults otherwise).
  Config config = LoadConfig(args.common);
  config.Set("render.frames=" + std::to_string(args.frames));
  if (config.root().value("scene", nlohmann::json::object()).count("props") == 0) {
    config.Set("scene.props=castle");
  }
  const sim::RenderConfig render = sim::RenderConfig::FromConfig(config);
  const auto threads = LimitThreads(args.common.threads);
  sim::TableTopScene table_top(render,
                               sim::LoadProxyModel(render.render.proxy, render.render.proxy_scale));
  // Both sensor modes over the same scene: the statistical model and structured light.
  std::vector<sim::SensorStatistics> rendered;
  std::vector<float> first_frames[2];
  std::string cause_table;  // structured light, first frame
  for (const sim::SensorMode mode : {sim::SensorMode::kStatistical,
                                     sim::SensorMode::kStructuredLight}) {
    sim::KinectSensorOptions sensor_options = render.sensor;
    sensor_options.mode = mode;
    const bool structured = mode == sim::SensorMode::kStructuredLight;
    const std::string name = structured ? "rendered SL" : "rendered stat.";
    sim::KinectSensor sensor(sensor_options, &table_top.scene(), table_top.table_T_camera());
    sensor.KeepMissingCauses(structured);
    sim::ErrorStructure mean;
    for (int i = 0; i < args.frames; ++i) {
      const double t = i / render.sensor.frame_rate;
      table_top.SetFrame(render.motion.TableTProxy(t), render.motion.SliderValue(t));
      const RgbdFrame frame = sensor.Render(i);
      const int width = frame.depth_intrinsics.width;
      const int height = frame.depth_intrinsics.height;
      sim::SensorCheckOptions frame_options = options;
      frame_options.intrinsics = frame.depth_intrinsics;
      frame_options.calibration = render.sensor.calibration;
      frame_options.noise = render.sensor.axial;
      const std::vector<float> depth_m =
          sim::DepthMetresFromUnits(frame.depth, frame.depth_scale);
      rendered.push_back(
          sim::ComputeSensorStatistics(name, depth_m, width, height, frame_options));
      if (i == 0) {
        first_frames[structured ? 1 : 0] = depth_m;
        structure_names.push_back(name);
        structures.push_back(sim::AnalyseErrorStructure(depth_m, width, height,
                                                        frame.depth_intrinsics,
                                                        render.sensor.calibration,
                                                        render.sensor.axial));
        if (structured) {
          cause_table = sim::FormatCauseTable(sim::ClassifyMissing(depth_m, width, height),
                                              sensor.missing_causes());
        }
      }
    }
    columns.push_back(rendered[rendered.size() - args.frames]);
  }
  std::cout << sim::FormatSensorTable(columns) << "\n"
            << sim::FormatRealismTable(structure_names, structures, 0, {2, 3}) << "\n"
            << "structured light, first frame: " << cause_table;
  if (!args.common.out_dir.empty()) {
    const std::filesystem::path out = args.common.out_dir;
    EnsureDirectory(out);
    nlohmann::json j = nlohmann::json::array();
    for (const auto& c : columns) j.push_back(sim::ToJson(c));
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& c : rendered) frames.push_back(sim::ToJson(c));
    nlohmann::json error_structure = nlohmann::json::object();
    for (size_t k = 0; k < structures.size(); ++k) {
      error_structure[structure_names[k]] = sim::ToJson(structures[k]);
    }
    nlohmann::json result = {
        {"columns", j}, {"rendered_frames", frames}, {"error_structure", error_structure}};
    WriteFileAtomically(out / "sensor_check.json", result.dump(2) + "\n");
    // Real (TUM) and rendered depth side by side, for a look (the TUM frame is 640 x 480 too).
    if (static_cast<size_t>(tum.width) * tum.height == first_frames[0].size()) {
      WriteRgbPng(out / "sensor_check.png",
                  sim::DepthSideBySide({&tum_m, &first_frames[0], &first_frames[1]}, tum.width,
                                       tum.height));
    }
    WriteFileAtomically(out / "config.resolved.json", render.ToJson().dump(2) + "\n");
    WriteFileAtomically(out / "run.json",
                        Provenance(argv, render.ToJson(), args.common.threads, {}).dump(2) + "\n");
  }
}

}  // namespace

void AddRenderCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto common = std::make_shared<CommonFlags>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Synthetic Kinect v1 RGB-D sequence (TUM RGB-D folder, fakenect dump, BOP)");
  AddCommonFlags(
      cmd, common.get(),
      {.config_help = "JSON config: sections render, camera, scene, hand, sensor, motion",
       .out_help = "Output folder (a TUM RGB-D folder)"});
  cmd->callback([common, argv] { RunRender(*common, argv); });
}

void AddSensorCheckCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<SensorCheckArgs>();
  // The real frames ship beside the project (../shared/data); a clone elsewhere finds them at the
  // workplace's fixed location.
  args->data = std::string(MMH_SOURCE_DIR) + "/../shared/data/real-rgbd";
  if (!std::filesystem::exists(args->data)) args->data = "/work/shared/data/real-rgbd";
  CLI::App* cmd = app.add_subcommand(
      "sensor-check",
      "Depth-step law, missing pixels and noise of real Kinect frames beside rendered ones");
  cmd->add_option("--data", args->data, "Folder with TUM_depth.png, NYU_depth.pgm, SUN_depth.png")
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Rendered frames to analyse")
      ->check(CLI::Range(1, 1000));
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "Render config for the rendered frames",
                  .out_help = "Write sensor_check.json here",
                  .out_required = false,
                  .quiet = false});
  cmd->callback([args, argv] { RunSensorCheck(*args, argv); });
}

MMH_REGISTER_COMMAND(20, AddRenderCommand);
MMH_REGISTER_COMMAND(90, AddSensorCheckCommand);

}  // namespace mmh::cli
