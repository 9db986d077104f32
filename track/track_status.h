// What the tracker says about a frame, and its name in the tables (status.csv, tracking_frames.csv,
// tracking_errors.csv). Apart from the tracker so that the readers of those tables (and their
// fuzz targets) need none of it.
#pragma once

#include <optional>
#include <string_view>

namespace mmh::track {

enum class TrackStatus { kTracked, kPredicted, kLost };

// "tracked", "predicted", "lost".
const char* TrackStatusName(TrackStatus status);

// The status named `name` (TrackStatusName's names); nullopt for anything else.
std::optional<TrackStatus> TrackStatusFromName(std::string_view name);

}  // namespace mmh::track
