// Montages of several objects (paper, "Creating montages for more than one object"): the first
// object's takes are composed with time warping; every later object's takes were recorded while
// the earlier montages played, so they all have the same length and are composed without warping.
// Spatial markers show an earlier object's montage pose at chosen frames.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "montage/compose.h"

namespace mmh::montage {

struct LayeredObject {
  std::string name;
  std::vector<Trajectory> takes;
  std::vector<Annotation> annotations;
  // Names of the takes then the annotations in messages (e.g. their files); empty: "<name> take
  // K" and "<name> annotation K".
  std::vector<std::string> names;
};

// objects[0] with options.time_warp as given; objects[1..] with time_warp = false. Takes of a later
// object must have equal lengths (InputError otherwise); a length different from the first
// object's montage is a warning in that object's summary.
std::vector<Montage> ComposeLayered(const std::vector<LayeredObject>& objects,
                                    const ComposeOptions& options);

struct SpatialMarker {
  std::string object;
  int frame = 0;
};

// The markers of a layered animation. Two markers of one object must be at least `min_spacing`
// frames apart (paper: "we do not allow two markers for the same object to be placed within 60
// frames of each other").
class SpatialMarkers {
 public:
  explicit SpatialMarkers(int min_spacing = 60);

  // Adds a marker; InputError if it is within min_spacing frames of one of the same object, or the
  // frame is negative.
  void Add(const std::string& object, int frame);
  // Removes the marker at exactly that frame; false if there is none.
  bool Remove(const std::string& object, int frame);
  // All markers, ordered by object then frame.
  std::vector<SpatialMarker> All() const;

  // The pose of each marker's object montage at its frame (InputError for an unknown object or a
  // frame past the montage's end).
  std::vector<Rigid3> Poses(const std::map<std::string, Trajectory>& montages) const;

 private:
  int min_spacing_;
  std::map<std::string, std::vector<int>> frames_;  // sorted per object
};

}  // namespace mmh::montage
