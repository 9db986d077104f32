#include "cli/compose_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
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
  // Layered objects (paper, "Creating montages for more than one object"): per object, its takes
  // and annotations (one occurrence of each flag per object), optional names and models.
  std::vector<std::vector<std::string>> layer_takes;
  std::vector<std::vector<std::string>> layer_annotations;
  std::vector<std::string> layer_names;
  std::vector<std::string> layer_models;
};

// The name of the first object (its glTF nodes are "proxy montage", ...; report/).
constexpr char kFirstObject[] = "proxy";

// The objects of the montage: the first from --takes / --annotations, one per --layer-takes. Their
// files are checked and read here (InputError naming the flag or the file).
std::vector<montage::LayeredObject> ReadObjects(const ComposeArgs& args) {
  auto check_pair = [](const std::string& flag, const std::vector<std::string>& takes,
                       const std::vector<std::string>& annotations) {
    if (takes.size() != annotations.size()) {
      ThrowBadValue(flag, std::to_string(annotations.size()) + " files for " +
                              std::to_string(takes.size()) + " takes",
                    "one annotation file per take, in the same order");
    }
  };
  check_pair("--annotations", args.takes, args.annotations);
  const std::size_t layers = args.layer_takes.size();
  if (args.layer_annotations.size() != layers) {
    ThrowBadValue("--layer-annotations", std::to_string(args.layer_annotations.size()) + " objects",
                  "one --layer-annotations per --layer-takes (" + std::to_string(layers) + ")");
  }
  for (const auto& [flag, list] : {std::pair{"--layer-names", &args.layer_names},
                                   std::pair{"--layer-models", &args.layer_models}}) {
    if (!list->empty() && list->size() != layers) {
      ThrowBadValue(flag, std::to_string(list->size()) + " values",
                    "none or one per layered object (" + std::to_string(layers) + ")");
    }
  }
  std::vector<montage::LayeredObject> objects(1 + layers);
  for (std::size_t i = 0; i <= layers; ++i) {
    montage::LayeredObject& object = objects[i];
    const auto& take_files = i == 0 ? args.takes : args.layer_takes[i - 1];
    const auto& annotation_files = i == 0 ? args.annotations : args.layer_annotations[i - 1];
    if (i > 0) {
      check_pair("--layer-annotations (object " + std::to_string(i + 1) + ")", take_files,
                 annotation_files);
    }
    object.name = i == 0 ? kFirstObject
                  : args.layer_names.empty() ? "object_" + std::to_string(i + 1)
                                             : args.layer_names[i - 1];
    // The name is a folder (layers/NAME) and a glTF node's prefix.
    const bool plain = !object.name.empty() &&
        std::all_of(object.name.begin(), object.name.end(), [](unsigned char c) {
          return std::isalnum(c) || c == '_' || c == '-';
        });
    if (i > 0 && (!plain || object.name == kFirstObject ||
                  std::any_of(objects.begin(), objects.begin() + i,
                              [&](const auto& o) { return o.name == object.name; }))) {
      ThrowBadValue("--layer-names", "'" + object.name + "'",
                    "a unique name of letters, digits, '_' or '-' other than 'proxy'");
    }
    for (const auto& path : take_files) {
      object.takes.push_back(ReadTum(path));
      object.names.push_back(path);
    }
    for (const auto& path : annotation_files) {
      object.annotations.push_back(ReadAnnotationCsv(path));
      object.names.push_back(path);
    }
  }
  return objects;
}

// The timeline, segments and summary of one object's montage into `dir`.
void WriteMontageFiles(const std::filesystem::path& dir, const montage::Montage& montage,
                       const nlohmann::json& summary, const std::string& what) {
  WriteTum(dir / "montage.tum", montage.trajectory,
           "MotionMontage montage of " + what + " (mmh compose)\n" +
               "timestamp tx ty tz qx qy qz qw");
  WriteFileAtomically(dir / "segments.csv", montage::SegmentsToCsv(montage.segments));
  WriteFileAtomically(dir / "timeline.csv", montage::TimelineToCsv(montage));
  WriteFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
}

void RunCompose(const ComposeArgs& args, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(args.common);
  config.RequireOnlySections({"montage"});
  const auto options = config.Get<montage::ComposeOptions>("montage");

  const auto threads = LimitThreads(args.common.threads);
  StartGitCommitLookup();  // for run.json, while the takes are read and composed

  // Everything is read and computed before anything is written: bad input leaves no output.
  const std::vector<montage::LayeredObject> objects = ReadObjects(args);
  // One object: montage::Compose; more: the first time-warped, the later ones not (layered.h).
  const std::vector<montage::Montage> montages = montage::ComposeLayered(objects, options);
  const montage::Montage& montage = montages.front();
  const std::vector<Trajectory>& takes = objects.front().takes;

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
    std::vector<report::MontageObject> scene(objects.size());
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const std::string& model = i == 0 ? args.model
                                 : args.layer_models.empty() ? std::string()
                                                             : args.layer_models[i - 1];
      scene[i].name = objects[i].name;
      scene[i].mesh = model.empty() ? report::OrientedStandIn()
                                    : report::LoadExportMesh(model, args.model_scale);
      scene[i].montage = montages[i].trajectory;
      scene[i].takes = objects[i].takes;
      scene[i].warps = montages[i].warps;
      scene[i].reference_take = options.reference_take;
      if (i == 0) scene[i].marker_frames = args.markers;
    }
    glb = report::EncodeGlb(report::MontageScene(scene));
  }

  nlohmann::json resolved;
  resolved["montage"] = ToJson(options);
  nlohmann::json summary = montage::SummaryToJson(montage.summary, montage.segments);
  summary["take_files"] = args.takes;
  summary["annotation_files"] = args.annotations;
  std::vector<nlohmann::json> layer_summaries;
  for (std::size_t i = 1; i < objects.size(); ++i) {
    nlohmann::json layer = montage::SummaryToJson(montages[i].summary, montages[i].segments);
    layer.erase("seconds");
    layer["name"] = objects[i].name;
    layer["take_files"] = args.layer_takes[i - 1];
    layer["annotation_files"] = args.layer_annotations[i - 1];
    layer_summaries.push_back(layer);
    summary["layers"].push_back({{"name", objects[i].name}, {"folder", "layers/" + objects[i].name}});
  }

  // Timings differ on every run: they go to run.json only, so summary.json is a pure function of
  // the inputs and config (DESIGN.md, "Determinism").
  const nlohmann::json timings = summary["seconds"];
  summary.erase("seconds");

  // The folder is complete or absent: every file goes into a staging folder beside it, which is
  // renamed into place at the end (a failure or a kill leaves no partial folder under --out).
  const std::filesystem::path out = args.common.out_dir;
  StagedFolder staged(out);
  const std::filesystem::path& dir = staged.staging();
  WriteMontageFiles(dir, montage, summary, std::to_string(takes.size()) + " takes");
  for (std::size_t i = 1; i < objects.size(); ++i) {
    const std::filesystem::path layer = dir / "layers" / objects[i].name;
    EnsureDirectory(layer);
    WriteMontageFiles(layer, montages[i], layer_summaries[i - 1],
                      objects[i].name + ": " + std::to_string(objects[i].takes.size()) +
                          " takes, layered");
  }
  if (!marker_poses.empty()) {
    WriteTum(dir / "markers.tum", marker_poses,
             "spatial markers: montage poses at the marked frames");
  }
  if (!glb.empty()) WriteFileAtomically(dir / "montage.glb", glb);
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
    for (std::size_t i = 1; i < objects.size(); ++i) {
      const auto& l = montages[i].summary;
      std::cout << "layer " << objects[i].name << ": " << l.montage_frames << " frames from "
                << l.takes << " takes, " << montages[i].segments.size() << " segments, total cost "
                << l.total_cost << " (layers/" << objects[i].name << "/)\n";
      for (const auto& w : l.warnings) std::cout << "warning: " << objects[i].name << ": " << w << '\n';
    }
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
  cmd->add_option("--layer-takes", args->layer_takes,
                  "A layered object's takes (TUM, equal lengths, recorded while the montage "
                  "played; composed without time warping); repeat the flag per object")
      ->expected(1, -1);
  cmd->add_option("--layer-annotations", args->layer_annotations,
                  "The layered object's annotation CSVs; one occurrence per --layer-takes")
      ->expected(1, -1);
  cmd->add_option("--layer-names", args->layer_names,
                  "Names of the layered objects (default object_2, ...): layers/NAME/")
      ->expected(1, -1);
  cmd->add_option("--layer-models", args->layer_models,
                  "Models of the layered objects for montage.glb (as --model; scaled by "
                  "--model-scale)")
      ->expected(1, -1);
  AddCommonFlags(cmd, &args->common, {.config_help = "JSON config with a 'montage' section"});
  cmd->callback([args, argv] { RunCompose(*args, argv); });
}

MMH_REGISTER_COMMAND(10, AddComposeCommand);

}  // namespace mmh::cli
