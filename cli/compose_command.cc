#include "cli/compose_command.h"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/command_registry.h"
#include "cli/provenance.h"
#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/config.h"
#include "core/error.h"
#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "montage/compose.h"
#include "montage/layered.h"
#include "report/trajectory_glb.h"

namespace mmh::cli {
namespace {

struct ComposeArgs {
  CommonFlags common;
  std::vector<std::string> takes;
  std::vector<std::string> annotations;
  std::vector<int> markers;
  std::string model;
  double model_scale = 1.0;
  bool no_glb = false;
};

void RunCompose(const ComposeArgs& args, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(args.common);
  config.RequireOnlySections({"montage"});
  const auto options = config.Get<montage::ComposeOptions>("montage");

  if (args.takes.size() != args.annotations.size()) {
    ThrowBadValue("--annotations",
                  std::to_string(args.annotations.size()) + " files for " +
                      std::to_string(args.takes.size()) + " takes",
                  "one annotation file per take, in the same order");
  }
  const auto threads = LimitThreads(args.common.threads);
  StartGitCommitLookup();  // for run.json, while the takes are read and composed

  // Everything is read and computed before anything is written: bad input leaves no output.
  std::vector<Trajectory> takes;
  std::vector<Annotation> annotations;
  std::vector<std::string> names;
  for (const auto& path : args.takes) {
    takes.push_back(ReadTum(path));
    names.push_back(path);
  }
  for (const auto& path : args.annotations) {
    annotations.push_back(ReadAnnotationCsv(path));
    names.push_back(path);
  }
  const montage::Montage montage = montage::Compose(takes, annotations, options, names);

  // Spatial markers on the montage's timeline (at least 60 frames apart, paper).
  Trajectory marker_poses;
  if (!args.markers.empty()) {
    montage::SpatialMarkers markers;
    for (int frame : args.markers) markers.Add("montage", frame);
    const auto poses = markers.Poses({{"montage", montage.trajectory}});
    const auto all = markers.All();
    for (std::size_t i = 0; i < all.size(); ++i) {
      marker_poses.timestamps.push_back(montage.trajectory.timestamps[all[i].frame]);
      marker_poses.poses.push_back(poses[i]);
    }
  }

  // montage.glb: the montage, every take warped and as recorded, the markers (report/).
  std::string glb;
  if (!args.no_glb) {
    report::MontageObject object;
    object.mesh = args.model.empty() ? report::OrientedStandIn()
                                     : report::LoadExportMesh(args.model, args.model_scale);
    object.montage = montage.trajectory;
    object.takes = takes;
    object.warps = montage.warps;
    object.reference_take = options.reference_take;
    object.marker_frames = args.markers;
    glb = report::EncodeGlb(report::MontageScene({object}));
  }

  nlohmann::json resolved;
  resolved["montage"] = ToJson(options);
  nlohmann::json summary = montage::SummaryToJson(montage.summary, montage.segments);
  summary["take_files"] = args.takes;
  summary["annotation_files"] = args.annotations;

  // Timings differ on every run: they go to run.json only, so summary.json is a pure function of
  // the inputs and config (DESIGN.md, "Determinism").
  const nlohmann::json timings = summary["seconds"];
  summary.erase("seconds");

  // The folder is complete or absent: every file goes into a staging folder beside it, which is
  // renamed into place at the end (a failure or a kill leaves no partial folder under --out).
  const std::filesystem::path out = args.common.out_dir;
  StagedFolder staged(out);
  const std::filesystem::path& dir = staged.staging();
  WriteTum(dir / "montage.tum", montage.trajectory,
           "MotionMontage montage of " + std::to_string(takes.size()) + " takes (mmh compose)\n" +
               "timestamp tx ty tz qx qy qz qw");
  WriteFileAtomically(dir / "segments.csv", montage::SegmentsToCsv(montage.segments));
  if (!marker_poses.empty()) {
    WriteTum(dir / "markers.tum", marker_poses,
             "spatial markers: montage poses at the marked frames");
  }
  WriteFileAtomically(dir / "timeline.csv", montage::TimelineToCsv(montage));
  if (!glb.empty()) WriteFileAtomically(dir / "montage.glb", glb);
  WriteFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
  WriteFileAtomically(dir / "config.resolved.json", resolved.dump(2) + "\n");
  WriteFileAtomically(dir / "run.json",
                      Provenance(argv, resolved, args.common.threads, timings).dump(2) + "\n");
  staged.Commit();

  if (!args.common.quiet) {
    const auto& s = montage.summary;
    std::cout << "montage: " << s.montage_frames << " frames from " << s.takes << " takes, "
              << montage.segments.size() << " segments (shortest " << s.shortest_segment_reference
              << " reference frames)\n"
              << "cost: total " << s.total_cost << " = data " << s.data_cost << " + smoothness "
              << s.smoothness_cost << "; without the segment constraint " << s.unconstrained_cost
              << " (+" << s.constraint_increase_percent << " %, " << s.unconstrained_short_segments
              << " short segments avoided)\n"
              << "time: " << s.seconds.total * 1e3 << " ms (dtw " << s.seconds.dtw * 1e3
              << ", smoothness " << s.seconds.smoothness * 1e3 << ", labelling "
              << s.seconds.labelling * 1e3 << ")\n";
    for (const auto& w : s.warnings) std::cout << "warning: " << w << '\n';
    std::cout << "written: " << out.string() << "/{montage.tum, segments.csv, timeline.csv, "
              << "summary.json, config.resolved.json, run.json"
              << (marker_poses.empty() ? "" : ", markers.tum") << (glb.empty() ? "" : ", montage.glb")
              << "}\n";
  }
}

}  // namespace

void AddComposeCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<ComposeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compose", "Montage from take trajectories (TUM) and their annotations (CSV)");
  cmd->add_option("--takes", args->takes, "Take trajectories (TUM); the first is the reference")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--annotations", args->annotations,
                  "Annotation CSVs (timestamp,value), one per take, same order")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--markers", args->markers,
                  "Spatial markers: montage frames (at least 60 apart); writes markers.tum")
      ->expected(1, -1);
  cmd->add_option("--model", args->model,
                  "Proxy model for montage.glb: Duplo assembly (.json), .obj or .ply "
                  "(default: an oriented stand-in)");
  cmd->add_option("--model-scale", args->model_scale, "Scale of --model (0.001 for millimetres)");
  cmd->add_flag("--no-glb", args->no_glb, "Do not write montage.glb");
  AddCommonFlags(cmd, &args->common, {.config_help = "JSON config with a 'montage' section"});
  cmd->callback([args, argv] { RunCompose(*args, argv); });
}

MMH_REGISTER_COMMAND(10, AddComposeCommand);

}  // namespace mmh::cli
