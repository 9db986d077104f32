// `mmh eval`: a tracked trajectory (TUM, camera_T_object) against a recording's ground truth with
// the BOP pose errors (ADD, ADD-S, MSSD, MSPD, VSD), BOP's average recall and the 5 deg / 5 cm and
// 2 deg / 2 cm recalls; the work is pipeline/recording_eval.h's. Writes eval_frames.csv,
// eval_objects.csv, eval_overall.csv, eval.json, config.resolved.json and run.json.
#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "core/error.h"
#include "metrics/pose_evaluation.h"
#include "pipeline/recording_eval.h"
#include "track/track_section.h"

namespace mmh::cli {
namespace {

struct EvalArgs {
  CommonFlags common;
  pipeline::RecordingEvalInputs inputs;
};

void PrintEvaluation(const std::filesystem::path& out,
                     const pipeline::RecordingEvaluation& result) {
  for (const auto& o : result.objects) {
    const metrics::BopRecall& r = o.recall;
    std::cout << "eval: object " << o.object << ", " << r.frames << " frames: AR "
              << FormatNumber(std::round(r.ar * 1000) / 1000) << " (VSD "
              << (r.has_vsd ? FormatNumber(std::round(r.ar_vsd * 1000) / 1000) : "-")
              << ", MSSD " << FormatNumber(std::round(r.ar_mssd * 1000) / 1000) << ", MSPD "
              << FormatNumber(std::round(r.ar_mspd * 1000) / 1000) << "), within 5 deg/5 cm "
              << FormatNumber(std::round(r.recall_5deg_5cm * 1000) / 10) << " %, 2 deg/2 cm "
              << FormatNumber(std::round(r.recall_2deg_2cm * 1000) / 10) << " %, median "
              << FormatNumber(std::round(r.median_rotation_deg * 100) / 100) << " deg "
              << FormatNumber(std::round(r.median_translation * 1e5) / 100) << " mm\n";
  }
  std::cout << "written: " << out.string()
            << "/{eval_frames.csv, eval_objects.csv, eval_overall.csv, eval.json, "
               "config.resolved.json, run.json}\n";
}

void RunEval(const EvalArgs& args, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(args.common);
  track::RefuseRunSection(config);
  config.RequireOnlySections({"track", "eval"});
  const auto options = config.Get<pipeline::RecordingEvalOptions>("track");
  options.Validate("track");
  const auto evaluation = config.Get<metrics::PoseEvaluationOptions>("eval");
  evaluation.Validate("eval");
  const pipeline::RecordingEvaluation result =
      pipeline::EvaluateRecording(args.inputs, options, evaluation);
  const nlohmann::json resolved = {{"track", ToJson(options)}, {"eval", ToJson(evaluation)}};
  pipeline::WriteRecordingEvaluation(
      args.common.out_dir, result, args.inputs, resolved,
      Provenance(argv, resolved, args.common.threads, nlohmann::json::object()));
  if (!args.common.quiet) PrintEvaluation(args.common.out_dir, result);
}

}  // namespace

void AddEvalCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "Pose metrics of a tracked trajectory against a recording's ground truth (BOP: ADD, "
      "ADD-S, MSSD, MSPD, VSD, average recall; 5 deg/5 cm, 2 deg/2 cm)");
  cmd->add_option("--input", args->inputs.recording,
                  "The recording: BOP scene, YCB-Video folder, or TUM RGB-D folder (camera.json)")
      ->required();
  cmd->add_option("--estimate", args->inputs.estimates,
                  "Estimates, repeatable: a tracked trajectory (TUM, camera_T_object; ID=FILE "
                  "for one of several objects) or a BOP result file (.csv: scene_id,im_id,obj_id,"
                  "score,R,t,time)")
      ->required();
  cmd->add_option("--model", args->inputs.models,
                  "The object's mesh (.ply or .obj), repeatable as ID=MESH to evaluate several "
                  "objects of a recording (the id in the recording)")
      ->required();
  cmd->add_option("--truth", args->inputs.truth,
                  "Ground truth (TUM) for a TUM folder; default: its groundtruth.txt");
  cmd->add_option("--models-info", args->inputs.models_info,
                  "BOP models_info.json with the object's symmetries (units of the model file); "
                  "default: models_info.json beside --model when there is one");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config: sections track, eval", .threads = false});
  cmd->callback([args, argv] { RunEval(*args, argv); });
}

MMH_REGISTER_COMMAND(42, AddEvalCommand);

}  // namespace mmh::cli
