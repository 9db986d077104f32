// `mmh track`: the tracker on a frame source (a TUM RGB-D folder, or a Kinect v1 through
// libfreenect) or a real recording; the work is pipeline/track_folder.h's (docs/tracker.md).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "cli/command_registry.h"
#include "cli/common_flags.h"
#include "cli/provenance.h"
#include "core/config.h"
#include "pipeline/track_folder.h"
#include "track/track_session.h"

namespace mmh::cli {
namespace {

struct TrackArgs {
  CommonFlags common;
  pipeline::TrackInputs inputs;
};

void PrintTrack(const std::filesystem::path& out, const pipeline::TrackFolderResult& result,
                const track::TrackConfig& config) {
  const track::TrackSummary& s = result.run.summary;
  std::cout << "track: " << s.frames << " frames from " << result.source << ": ";
  if (config.track.proxy) {
    std::cout << s.tracked << " tracked, " << s.predicted << " predicted, " << s.lost << " lost ("
              << s.detections << " detections)";
  } else {
    std::cout << "proxy not tracked (track.proxy=false)";
  }
  if (!result.run.slider.empty()) std::cout << "; slider found in " << s.slider_found;
  std::cout << "; " << (s.seconds > 0 ? s.frames / s.seconds : 0.0) << " frames/s\n";
  if (!result.calibrated) {
    std::cout << "note: no setup calibration (--setup or scene.json): table frame from the "
                 "estimated plane, slider not read\n";
  }
  std::cout << "written: " << out.string() << "/{";
  for (size_t i = 0; i < result.written.size(); ++i) {
    std::cout << (i ? ", " : "") << result.written[i];
  }
  std::cout << "}\n";
}

void RunTrack(const TrackArgs& args, const std::vector<std::string>& argv) {
  const Config config = LoadConfig(args.common);
  const track::TrackConfig track_config = track::TrackConfig::FromConfig(config);
  const auto threads = LimitThreads(args.common.threads);
  ProgressBar progress_bar(ShowProgress(args.common), "track");
  pipeline::TrackFolderOptions options;
  options.progress = [&](std::int64_t done, std::int64_t total) {
    progress_bar.Update(done, total);
  };
  options.provenance = [&](const nlohmann::json& resolved, const nlohmann::json& timings) {
    return Provenance(argv, resolved, args.common.threads, timings);
  };
  const std::filesystem::path out = args.common.out_dir;
  const pipeline::TrackFolderResult result =
      pipeline::TrackToFolder(args.inputs, track_config, out, options);
  progress_bar.Finish();
  for (const std::string& warning : result.run.summary.warnings) {
    std::cerr << "warning: " << warning << "\n";
  }
  if (!args.common.quiet) PrintTrack(out, result, track_config);
  // Failures of the work, not of the input's form (exit 1): status.csv says why.
  if (!track_config.track.proxy) {
    if (result.run.summary.slider_found == 0) {
      throw std::runtime_error("the slider block was found in no frame; see " +
                               (out / "status.csv").string());
    }
    return;
  }
  if (result.run.summary.tracked == 0) {
    throw std::runtime_error("no frame was tracked (a model that does not match the proxy?); see " +
                             (out / "status.csv").string());
  }
}

}  // namespace

void AddTrackCommand(CLI::App& app, const std::vector<std::string>& argv) {
  auto args = std::make_shared<TrackArgs>();
  CLI::App* cmd = app.add_subcommand(
      "track",
      "Tracker on a frame source: proxy trajectory (TUM), per-frame status, slider "
      "annotation (CSV)");
  cmd->add_option("--input", args->inputs.input,
                  "A TUM RGB-D folder (ours or a public sequence), a real recording with ground "
                  "truth (BOP scene, YCB-Video folder), or 'freenect' for a Kinect v1")
      ->required();
  cmd->add_option("--model", args->inputs.model,
                  "The proxy's mesh (.ply or .obj), e.g. model.ply of a rendered take; "
                  "required unless --set track.proxy=false (slider only)");
  cmd->add_option("--setup", args->inputs.setup,
                  "Setup calibration (scene.json keys: camera_T_table, table.play_area_*, "
                  "table.like_box_*); default: INPUT/scene.json when present");
  AddCommonFlags(cmd, &args->common,
                 {.config_help = "JSON config: sections track, tracker, slider, freenect"});
  cmd->callback([args, argv] { RunTrack(*args, argv); });
}

MMH_REGISTER_COMMAND(40, AddTrackCommand);

}  // namespace mmh::cli
