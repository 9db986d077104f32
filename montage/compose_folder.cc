#include "montage/compose_folder.h"

#include <nlohmann/json.hpp>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/options.h"
#include "core/staged_folder.h"
#include "core/tum_io.h"

namespace mmh::montage {
namespace {

// The poses of the first montage at the marker frames (SpatialMarkers checks their spacing and
// range: InputError).
Trajectory MarkerPoses(const Montage& montage, const std::vector<int>& marker_frames) {
  Trajectory poses;
  if (marker_frames.empty()) return poses;
  SpatialMarkers markers;
  for (int frame : marker_frames) markers.Add("montage", frame);
  const std::vector<Rigid3> at = markers.Poses({{"montage", montage.trajectory}});
  const std::vector<SpatialMarker> all = markers.All();
  for (std::size_t i = 0; i < all.size(); ++i) {
    poses.timestamps.push_back(montage.trajectory.timestamps[all[i].frame]);
    poses.poses.push_back(at[i]);
  }
  return poses;
}

// summary.json of the first object, which names the later objects' folders.
nlohmann::json FirstSummary(const std::vector<ComposeObjectInput>& objects,
                            const std::vector<Montage>& montages) {
  nlohmann::json summary = SummaryToJson(montages[0].summary, montages[0].segments);
  summary["take_files"] = objects[0].take_files;
  summary["annotation_files"] = objects[0].annotation_files;
  for (std::size_t i = 1; i < objects.size(); ++i) {
    const std::string& name = objects[i].object.name;
    summary["layers"].push_back({{"name", name}, {"folder", "layers/" + name}});
  }
  return summary;
}

// summary.json of a later object (its timings are in the first object's).
nlohmann::json LayerSummary(const ComposeObjectInput& object, const Montage& montage) {
  nlohmann::json summary = SummaryToJson(montage.summary, montage.segments);
  summary.erase("seconds");
  summary["name"] = object.object.name;
  summary["take_files"] = object.take_files;
  summary["annotation_files"] = object.annotation_files;
  return summary;
}

// The timeline, segments and summary of one object's montage into `dir`.
void WriteMontageFiles(const std::filesystem::path& dir, const Montage& montage,
                       const nlohmann::json& summary, const std::string& what) {
  WriteTum(dir / "montage.tum", montage.trajectory,
           "MotionMontage montage of " + what + " (mmh compose)\n" +
               "timestamp tx ty tz qx qy qz qw");
  WriteFileAtomically(dir / "segments.csv", SegmentsToCsv(montage.segments));
  WriteFileAtomically(dir / "timeline.csv", TimelineToCsv(montage));
  WriteFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
}

}  // namespace

ComposeObjectInput ReadComposeObject(const std::string& name,
                                     const std::vector<std::string>& take_files,
                                     const std::vector<std::string>& annotation_files) {
  ComposeObjectInput input;
  input.object.name = name;
  input.take_files = take_files;
  input.annotation_files = annotation_files;
  for (const std::string& path : take_files) {
    input.object.takes.push_back(ReadTum(path));
    input.object.names.push_back(path);
  }
  for (const std::string& path : annotation_files) {
    input.object.annotations.push_back(ReadAnnotationCsv(path));
    input.object.names.push_back(path);
  }
  return input;
}

ComposeFolderResult ComposeToFolder(const std::vector<ComposeObjectInput>& objects,
                                    const ComposeOptions& options,
                                    const std::filesystem::path& out,
                                    const ComposeFolderOptions& folder_options) {
  // Everything is computed before anything is written: bad input leaves no output.
  std::vector<LayeredObject> layered;
  for (const ComposeObjectInput& o : objects) layered.push_back(o.object);
  ComposeFolderResult result;
  result.montages = ComposeLayered(layered, options);
  const Montage& first = result.montages.front();
  result.marker_poses = MarkerPoses(first, folder_options.marker_frames);
  const std::string glb = folder_options.glb ? folder_options.glb(result.montages) : "";

  nlohmann::json resolved;
  resolved["montage"] = ToJson(options);
  nlohmann::json summary = FirstSummary(objects, result.montages);
  // Timings differ on every run: they go to run.json only, so summary.json is a pure function of
  // the inputs and config (DESIGN.md, "Determinism").
  const nlohmann::json timings = summary["seconds"];
  summary.erase("seconds");

  // The folder is complete or absent: a failure or a kill leaves no partial folder under `out`.
  StagedFolder staged(out);
  const std::filesystem::path& dir = staged.staging();
  WriteMontageFiles(dir, first, summary, std::to_string(objects[0].object.takes.size()) + " takes");
  for (std::size_t i = 1; i < objects.size(); ++i) {
    const LayeredObject& object = objects[i].object;
    const std::filesystem::path layer = dir / "layers" / object.name;
    EnsureDirectory(layer);
    WriteMontageFiles(layer, result.montages[i], LayerSummary(objects[i], result.montages[i]),
                      object.name + ": " + std::to_string(object.takes.size()) + " takes, layered");
  }
  result.written = {"montage.tum", "segments.csv", "timeline.csv", "summary.json"};
  if (!result.marker_poses.empty()) {
    WriteTum(dir / "markers.tum", result.marker_poses,
             "spatial markers: montage poses at the marked frames");
  }
  if (!glb.empty()) WriteFileAtomically(dir / "montage.glb", glb);
  WriteFileAtomically(dir / "config.resolved.json", resolved.dump(2) + "\n");
  const nlohmann::json provenance = folder_options.provenance
                                        ? folder_options.provenance(resolved, timings)
                                        : nlohmann::json{{"writer", "mmh"}, {"seconds", timings}};
  WriteFileAtomically(dir / "run.json", provenance.dump(2) + "\n");
  staged.Commit();
  result.written.insert(result.written.end(), {"config.resolved.json", "run.json"});
  if (!result.marker_poses.empty()) result.written.push_back("markers.tum");
  if (!glb.empty()) result.written.push_back("montage.glb");
  return result;
}

}  // namespace mmh::montage
