#include "montage/layered.h"

#include <algorithm>
#include <cstdlib>

#include "core/error.h"

namespace mmh::montage {

std::vector<Montage> ComposeLayered(const std::vector<LayeredObject>& objects,
                                    const ComposeOptions& options) {
  if (objects.empty()) ThrowBadValue("layered objects", "none", "at least one object");
  std::vector<Montage> montages;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const LayeredObject& object = objects[i];
    ComposeOptions object_options = options;
    // Later objects were recorded while the earlier montages played: equal lengths, no warp.
    if (i > 0) object_options.time_warp = false;
    std::vector<std::string> names = object.names;
    if (names.empty()) {
      for (std::size_t k = 0; k < object.takes.size(); ++k) {
        names.push_back(object.name + " take " + std::to_string(k));
      }
      for (std::size_t k = 0; k < object.annotations.size(); ++k) {
        names.push_back(object.name + " annotation " + std::to_string(k));
      }
    }
    Montage montage = Compose(object.takes, object.annotations, object_options, names);
    if (i > 0 && montage.trajectory.size() != montages[0].trajectory.size()) {
      montage.summary.warnings.push_back(
          object.name + "'s takes have " + std::to_string(object.takes[0].size()) + " frames but " +
          objects[0].name + "'s montage has " + std::to_string(montages[0].trajectory.size()));
    }
    montages.push_back(std::move(montage));
  }
  return montages;
}

SpatialMarkers::SpatialMarkers(int min_spacing) : min_spacing_(min_spacing) {
  if (min_spacing < 0) {
    ThrowBadValue("spatial marker spacing", std::to_string(min_spacing), "frames >= 0");
  }
}

void SpatialMarkers::Add(const std::string& object, int frame) {
  if (frame < 0) {
    ThrowBadValue("spatial marker of " + object, "frame " + std::to_string(frame), "a frame >= 0");
  }
  auto& frames = frames_[object];
  for (int other : frames) {
    if (std::abs(other - frame) < min_spacing_) {
      ThrowBadValue("spatial marker of " + object, "frame " + std::to_string(frame),
                    "at least " + std::to_string(min_spacing_) +
                        " frames from its marker at frame " + std::to_string(other));
    }
  }
  frames.insert(std::upper_bound(frames.begin(), frames.end(), frame), frame);
}

bool SpatialMarkers::Remove(const std::string& object, int frame) {
  auto it = frames_.find(object);
  if (it == frames_.end()) return false;
  auto pos = std::find(it->second.begin(), it->second.end(), frame);
  if (pos == it->second.end()) return false;
  it->second.erase(pos);
  return true;
}

std::vector<SpatialMarker> SpatialMarkers::All() const {
  std::vector<SpatialMarker> all;
  for (const auto& [object, frames] : frames_) {
    for (int f : frames) all.push_back({object, f});
  }
  return all;
}

std::vector<Rigid3> SpatialMarkers::Poses(const std::map<std::string, Trajectory>& montages) const {
  std::vector<Rigid3> poses;
  for (const auto& marker : All()) {
    const auto it = montages.find(marker.object);
    if (it == montages.end()) {
      ThrowBadValue("spatial marker", "object '" + marker.object + "'", "an object with a montage");
    }
    if (marker.frame >= static_cast<int>(it->second.size())) {
      ThrowBadValue("spatial marker of " + marker.object, "frame " + std::to_string(marker.frame),
                    "a frame below the montage's " + std::to_string(it->second.size()));
    }
    poses.push_back(it->second.poses[marker.frame]);
  }
  return poses;
}

}  // namespace mmh::montage
