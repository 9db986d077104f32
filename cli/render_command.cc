#include "cli/render_command.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/compose_command.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/image_io.h"
#include "sim/render_session.h"
#include "sim/sensor_check.h"

namespace mmh::cli {
namespace {

void RunRender(const CommonFlags& common, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(common);
  const sim::RenderConfig render = sim::RenderConfig::FromConfig(config);
  const auto threads = LimitThreads(common.threads);
  const bool bar = !common.quiet && isatty(STDERR_FILENO);
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
  sim::KinectSensor sensor(render.sensor, &table_top.scene(), table_top.table_T_camera());
  std::vector<float> depth;
  int width = 0, height = 0;
  std::vector<sim::SensorStatistics> rendered;
  for (int i = 0; i < args.frames; ++i) {
    const double t = i / render.sensor.frame_rate;
    table_top.SetFrame(render.motion.TableTProxy(t), render.motion.SliderValue(t));
    const RgbdFrame frame = sensor.Render(i);
    width = frame.depth_intrinsics.width;
    height = frame.depth_intrinsics.height;
    sim::SensorCheckOptions frame_options = options;
    frame_options.intrinsics = frame.depth_intrinsics;
    frame_options.calibration = render.sensor.calibration;
    frame_options.noise = render.sensor.axial;
    rendered.push_back(sim::ComputeSensorStatistics(
        "rendered", sim::DepthMetresFromUnits(frame.depth, frame.depth_scale), width, height,
        frame_options));
  }
  columns.push_back(rendered.front());
  std::cout << sim::FormatSensorTable(columns);
  if (!args.common.out_dir.empty()) {
    const std::filesystem::path out = args.common.out_dir;
    EnsureDirectory(out);
    nlohmann::json j = nlohmann::json::array();
    for (const auto& c : columns) j.push_back(sim::ToJson(c));
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& c : rendered) frames.push_back(sim::ToJson(c));
    nlohmann::json result = {{"columns", j}, {"rendered_frames", frames}};
    WriteFileAtomically(out / "sensor_check.json", result.dump(2) + "\n");
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
  cmd->add_option("--config", common->config_file,
                  "JSON config: sections render, camera, scene, hand, sensor, motion");
  cmd->add_option("--set", common->sets, "Override: key.path=value (JSON value), repeatable")
      ->take_all();
  cmd->add_option("--out", common->out_dir, "Output folder (a TUM RGB-D folder)")->required();
  cmd->add_option("--threads", common->threads, "Worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--quiet", common->quiet, "Print nothing on success");
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
  cmd->add_option("--config", args->common.config_file, "Render config for the rendered frames");
  cmd->add_option("--set", args->common.sets, "Override: key.path=value, repeatable")->take_all();
  cmd->add_option("--out", args->common.out_dir, "Write sensor_check.json here");
  cmd->add_option("--threads", args->common.threads, "Worker threads (0: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([args, argv] { RunSensorCheck(*args, argv); });
}

MMH_REGISTER_COMMAND(20, AddRenderCommand);
MMH_REGISTER_COMMAND(90, AddSensorCheckCommand);

}  // namespace mmh::cli
