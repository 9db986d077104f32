// The config of track as that command resolves it (cli/track_command.cc), registered with
// sweep/command_config.h at start-up. Built as the object library mmh::sweep_resolvers, not into
// mmh::sweep: the code that reads it links the tracker's frame sources, which the light mmh must
// not load. If the command changes how it reads its config, update this file.
#include "core/config.h"
#include "sweep/command_config.h"
#include "track/track_session.h"

namespace mmh::sweep {
namespace {

nlohmann::json ResolveTrackConfig(const Config& config) {
  return track::TrackConfig::FromConfig(config).ToJson();
}

[[maybe_unused]] const bool kRegistered =
    RegisterConfigResolver(SweepCommand::kTrack, ResolveTrackConfig);

}  // namespace
}  // namespace mmh::sweep
