#include "cli/render_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <memory>
#include <optional>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "pipeline/depth_sequence.h"
#include "sim/render_session.h"
#include "sim/sensor_check_run.h"

namespace mmh::cli {
namespace {

void RunRender(const CommonFlags& common, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(common);
  const sim::RenderConfig render = sim::RenderConfig::FromConfig(config);
  const people::PeopleConfig people = people::PeopleConfig::FromConfig(config);
  const auto threads = LimitThreads(common.threads);
  const bool bar = ShowProgress(common);
  const std::filesystem::path out = common.out_dir;
  nlohmann::json resolved = render.ToJson();
  people.AddToJson(resolved);
  nlohmann::json timings;
  ProgressBar progress_bar(bar, "render");
  const auto progress = [&](int done, int total) { progress_bar.Update(done, total); };
  // The run's own files go into the staging folder too: the folder appears whole or not at all.
  const auto add_run_files = [&](const std::filesystem::path& staging,
                                 const sim::RenderSummary& summary) {
    timings = summary.ToJson();
    WriteFileAtomically(staging / "render_summary.json", timings.dump(2) + "\n");
    WriteFileAtomically(staging / "config.resolved.json", resolved.dump(2) + "\n");
    WriteFileAtomically(staging / "run.json",
                        Provenance(argv, resolved, common.threads, timings).dump(2) + "\n");
  };
  const sim::RenderSummary summary = sim::RenderSequence(render, people, out, progress, add_run_files);
  if (!common.quiet) {
    std::cout << "render: " << summary.frames << " frames in " << summary.seconds << " s ("
              << timings["frames_per_second"].get<double>() << " frames/s rendering; writing "
              << summary.write_seconds << " s), " << 100 * summary.missing_fraction
              << " % depth missing\n"
              << "written: " << out.string()
              << "/{rgb/, depth/, rgb.txt, depth.txt, groundtruth.txt, camera.json, model.ply, "
                 "slider.csv, scene.json, render_summary.json, config.resolved.json, run.json"
              << (people.scenario.story.empty() ? ""
                                              : ", take.tum, take.csv, flaws.csv, participant.json")
              << (render.render.bop ? ", bop/" : "") << "}"
              << (render.render.fakenect ? " and " + out.string() + ".fakenect/" : "") << "\n";
  }
}

// Frames of --kinect-sequence read at most.
constexpr int kKinectSequenceFrames = 10;

struct SensorCheckArgs {
  CommonFlags common;
  std::string data;
  std::string sequence;
  std::string kinect_sequence;  // real Kinect v1 frames for the step law
  // Like for like (docs/sensor.md): the sequence's first frame beside the same view rendered.
  std::string view, view_model, view_trajectory, view_label;
  int view_object = 8;
  int patterns = 8;
  int view_frames = 10;
  bool view_frames_given = false;  // else as many as the --sequence has, up to view_frames
  int frames = 3;
};

void RunSensorCheck(const SensorCheckArgs& args, const std::vector<std::string>& argv) {
  // Rendered frames of the table-top scene with the castle, from the config (defaults otherwise).
  Config config = LoadConfig(args.common);
  config.Set("render.frames=" + std::to_string(args.frames));
  if (config.root().value("scene", nlohmann::json::object()).count("props") == 0) {
    config.Set("scene.props=castle");
  }
  const sim::RenderConfig render = sim::RenderConfig::FromConfig(config);
  const auto threads = LimitThreads(args.common.threads);
  std::optional<sim::DepthSequence> sequence;
  if (!args.sequence.empty()) {
    sequence = pipeline::ReadDepthSequence(args.sequence, std::end(sim::kTemporalLags)[-1] + 1);
  }
  std::optional<sim::DepthSequence> kinect;
  if (!args.kinect_sequence.empty()) {
    kinect = pipeline::ReadDepthSequence(args.kinect_sequence, -kKinectSequenceFrames);
  }
  std::optional<sim::RealView> view;
  if (!args.view.empty()) {
    if (args.sequence.empty()) {
      ThrowBadValue("--view", "\"" + args.view + "\"", "a --sequence whose first frame it shows");
    }
    std::string trajectory = args.view_trajectory;
    if (trajectory.empty()) {
      trajectory = std::filesystem::path(args.view).replace_extension(".tum").string();
    }
    view = pipeline::ReadRealView(args.sequence, args.view_label, args.view_object, args.view,
                                  args.view_model, trajectory, render.sensor,
                                  args.view_frames_given ? args.view_frames : -args.view_frames);
    view->patterns = args.patterns;
  }
  const sim::SensorCheckReport report =
      sim::RunSensorCheck(args.data, render, args.frames, sequence ? &*sequence : nullptr,
                          view ? &*view : nullptr, kinect ? &*kinect : nullptr);
  std::cout << report.Format();
  if (!args.common.out_dir.empty()) {
    const std::filesystem::path out = args.common.out_dir;
    sim::WriteSensorCheck(report, out);
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
  // YCB-Video's video 0000 (Asus Xtion, structured light; tests/data/real/ycbv/PROVENANCE.md): a
  // nearly static view, for the temporal structure of the errors.
  args->sequence = std::string(MMH_SOURCE_DIR) + "/tests/data/real/ycbv/data/0000";
  cmd->add_option("--sequence", args->sequence,
                  "Real recording (BOP, YCB-Video or TUM folder) of a nearly static view: the "
                  "temporal structure of its errors; empty: none")
      ->capture_default_str();
  // Two frames of TUM's freiburg1_xyz (Kinect v1; tests/data/real/tum/.../PROVENANCE.md): depth
  // steps of many sizes for the step law.
  args->kinect_sequence =
      std::string(MMH_SOURCE_DIR) + "/tests/data/real/tum/rgbd_dataset_freiburg1_xyz";
  cmd->add_option("--kinect-sequence", args->kinect_sequence,
                  "Real Kinect v1 recording (TUM, BOP or YCB-Video folder; its first " +
                      std::to_string(kKinectSequenceFrames) +
                      " frames at most) whose missing bands beside depth steps the step law "
                      "compares with the model's; empty: none")
      ->capture_default_str();
  // The same view rendered (tests/data/real/ycbv/views, render_real_view.py): the gelatin box of
  // video 0000 where its truth puts it, seen from where the real camera stood.
  const std::string ycbv = std::string(MMH_SOURCE_DIR) + "/tests/data/real/ycbv";
  args->view = ycbv + "/views/009_gelatin_box_static.json";
  args->view_model = ycbv + "/models_real/009_gelatin_box.obj";
  args->view_label = ycbv + "/data/0000/000001-label.png";
  cmd->add_option("--view", args->view,
                  "Render config of the --sequence's view (camera and object placed as in its "
                  "first frame) for the like-for-like comparison; empty: none")
      ->capture_default_str();
  cmd->add_option("--view-model", args->view_model, "The object's model (the view's proxy)")
      ->capture_default_str();
  cmd->add_option("--view-trajectory", args->view_trajectory,
                  "The object's poses (TUM, table frame); empty: --view with the extension .tum");
  cmd->add_option("--view-label", args->view_label,
                  "Label image of the sequence's first frame (8-bit, YCB-Video -label.png)")
      ->capture_default_str();
  cmd->add_option("--view-object", args->view_object, "The object's value in the label image")
      ->capture_default_str();
  cmd->add_option("--view-frames", args->view_frames,
                  "Real frames of the view compared (the first and the next ones, their labels "
                  "named as --view-label's with the frame number counted up): the real side's "
                  "spread; by default as many as the --sequence has, up to 10")
      ->check(CLI::Range(1, 1000))
      ->each([args](const std::string&) { args->view_frames_given = true; })
      ->capture_default_str();
  cmd->add_option("--patterns", args->patterns,
                  "Speckle patterns the view is rendered with in structured light (the config's "
                  "pattern_seed and the next ones): the like-for-like ratios' mean and spread")
      ->check(CLI::Range(1, 100))
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
