#include "track/track_status.h"

namespace mmh::track {

const char* TrackStatusName(TrackStatus status) {
  switch (status) {
    case TrackStatus::kTracked:
      return "tracked";
    case TrackStatus::kPredicted:
      return "predicted";
    case TrackStatus::kLost:
      return "lost";
  }
  return "?";
}

std::optional<TrackStatus> TrackStatusFromName(std::string_view name) {
  for (const TrackStatus s : {TrackStatus::kTracked, TrackStatus::kPredicted, TrackStatus::kLost}) {
    if (name == TrackStatusName(s)) return s;
  }
  return std::nullopt;
}

}  // namespace mmh::track
