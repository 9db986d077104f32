#include "cli/compose_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "core/error.h"
#include "montage/compose.h"
#include "montage/compose_folder.h"
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

// The objects of the montage: the first from --takes / --annotations, one per --layer-takes. The
// flags are checked here (InputError naming the flag); the files are read by
// montage::ReadComposeObject (InputError naming the file).
std::vector<montage::ComposeObjectInput> ReadObjects(const ComposeArgs& args) {
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
  std::vector<montage::ComposeObjectInput> objects;
  objects.push_back(montage::ReadComposeObject(kFirstObject, args.takes, args.annotations));
  for (std::size_t i = 1; i <= layers; ++i) {
    check_pair("--layer-annotations (object " + std::to_string(i + 1) + ")",
               args.layer_takes[i - 1], args.layer_annotations[i - 1]);
    const std::string name =
        args.layer_names.empty() ? "object_" + std::to_string(i + 1) : args.layer_names[i - 1];
    // The name is a folder (layers/NAME) and a glTF node's prefix.
    const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_' || c == '-';
    });
    if (!plain || name == kFirstObject ||
        std::any_of(objects.begin(), objects.end(),
                    [&](const auto& o) { return o.object.name == name; })) {
      ThrowBadValue("--layer-names", "'" + name + "'",
                    "a unique name of letters, digits, '_' or '-' other than 'proxy'");
    }
    objects.push_back(
        montage::ReadComposeObject(name, args.layer_takes[i - 1], args.layer_annotations[i - 1]));
  }
  return objects;
}

// montage.glb: every object's montage, its takes warped and as recorded, the first object's
// markers (report/trajectory_glb.h).
std::string MontageGlb(const ComposeArgs& args,
                       const std::vector<montage::ComposeObjectInput>& objects,
                       const std::vector<montage::Montage>& montages, int reference_take) {
  std::vector<report::MontageObject> scene(objects.size());
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const std::string& model = i == 0                      ? args.model
                               : args.layer_models.empty() ? std::string()
                                                           : args.layer_models[i - 1];
    scene[i].name = objects[i].object.name;
    scene[i].mesh = model.empty() ? report::OrientedStandIn()
                                  : report::LoadExportMesh(model, args.model_scale);
    scene[i].montage = montages[i].trajectory;
    scene[i].takes = objects[i].object.takes;
    scene[i].warps = montages[i].warps;
    scene[i].reference_take = reference_take;
    if (i == 0) scene[i].marker_frames = args.markers;
  }
  return report::EncodeGlb(report::MontageScene(scene));
}

void PrintCompose(const std::filesystem::path& out,
                  const std::vector<montage::ComposeObjectInput>& objects,
                  const montage::ComposeFolderResult& result) {
  const montage::Montage& montage = result.montages.front();
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
    const std::string& name = objects[i].object.name;
    const auto& l = result.montages[i].summary;
    std::cout << "layer " << name << ": " << l.montage_frames << " frames from " << l.takes
              << " takes, " << result.montages[i].segments.size() << " segments, total cost "
              << l.total_cost << " (layers/" << name << "/)\n";
    for (const auto& w : l.warnings) std::cout << "warning: " << name << ": " << w << '\n';
  }
  std::cout << "written: " << out.string() << "/{";
  for (std::size_t i = 0; i < result.written.size(); ++i) {
    std::cout << (i ? ", " : "") << result.written[i];
  }
  std::cout << "}\n";
}

void RunCompose(const ComposeArgs& args, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(args.common);
  config.RequireOnlySections({"montage"});
  const auto options = config.Get<montage::ComposeOptions>("montage");

  const auto threads = LimitThreads(args.common.threads);
  StartGitCommitLookup();  // for run.json, while the takes are read and composed

  const std::vector<montage::ComposeObjectInput> objects = ReadObjects(args);
  montage::ComposeFolderOptions folder;
  folder.marker_frames = args.markers;
  folder.provenance = [&](const nlohmann::json& resolved, const nlohmann::json& timings) {
    return Provenance(argv, resolved, args.common.threads, timings);
  };
  if (!args.no_glb) {
    folder.glb = [&](const std::vector<montage::Montage>& montages) {
      return MontageGlb(args, objects, montages, options.reference_take);
    };
  }
  const montage::ComposeFolderResult result =
      montage::ComposeToFolder(objects, options, args.common.out_dir, folder);
  if (!args.common.quiet) PrintCompose(args.common.out_dir, objects, result);
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
