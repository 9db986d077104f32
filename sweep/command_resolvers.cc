// The configs of run, study and track as those commands resolve them (cli/run_command.cc,
// cli/study_command.cc, cli/track_command.cc), registered with sweep/command_config.h at start-up.
// Built as the object library mmh::sweep_resolvers, not into mmh::sweep: the code that reads
// these configs links the renderer and the tracker, which the light mmh must not load.
// If a command changes how it reads its config, update this file.
#include "core/config.h"
#include "pipeline/animator_run.h"
#include "study/simulated_study.h"
#include "sweep/command_config.h"
#include "track/track_session.h"

namespace mmh::sweep {
namespace {

nlohmann::json ResolveRunConfig(const Config& config) {
  return pipeline::RunConfig::FromConfig(config).ToJson();
}

nlohmann::json ResolveStudyConfig(const Config& config) {
  const study::StudyConfig study_config = study::StudyConfig::FromConfig(config);
  study_config.study.Validate("study");
  return study_config.ToJson();
}

nlohmann::json ResolveTrackConfig(const Config& config) {
  return track::TrackConfig::FromConfig(config).ToJson();
}

[[maybe_unused]] const bool kRegistered =
    RegisterConfigResolver(SweepCommand::kRun, ResolveRunConfig) &&
    RegisterConfigResolver(SweepCommand::kStudy, ResolveStudyConfig) &&
    RegisterConfigResolver(SweepCommand::kTrack, ResolveTrackConfig);

}  // namespace
}  // namespace mmh::sweep
