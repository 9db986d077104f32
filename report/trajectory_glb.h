// glTF scenes of trajectories: one proxy animated by a TUM trajectory (`mmh export`), and a
// montage with its takes and spatial markers (`mmh compose`, `mmh run`: montage.glb).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/trajectory.h"
#include "core/triangle_mesh.h"
#include "report/gltf_scene.h"

namespace mmh::report {

// The proxy's mesh from a Duplo assembly (.json), an .obj or a .ply (times `scale`); an unreadable
// or invalid file is an InputError naming it.
TriangleMesh LoadExportMesh(const std::filesystem::path& path, double scale = 1.0);

// When no model is given: a light grey 60 x 40 x 30 mm block (its bottom at z = 0) with a red bar
// along its +x, a green bar along +y and a blue bar along +z, so that every rotation shows.
TriangleMesh OrientedStandIn();

struct TrajectoryExportOptions {
  // The frame the trajectory's poses map the proxy into (table_T_proxy by default).
  TrajectoryFrame frame = TrajectoryFrame::kTable;
  // Name of the animated node and of the animation.
  std::string name = "proxy";
};

// One node with `mesh`, animated by frame_T_proxy (one keyframe per pose, times from the first
// timestamp, which is the track's time origin). The trajectory is checked first (finite values,
// unit quaternions to 1e-6, increasing timestamps: InputError naming options.name).
GltfScene TrajectoryScene(const TriangleMesh& mesh, const Trajectory& frame_T_proxy,
                          const TrajectoryExportOptions& options = {});

// One object of a (possibly layered) montage.
struct MontageObject {
  std::string name = "proxy";
  TriangleMesh mesh;
  Trajectory montage;               // table_T_proxy of the montage
  std::vector<Trajectory> takes;    // as recorded, table_T_proxy
  std::vector<std::vector<int>> warps;  // per take, the source frame at each reference frame
  int reference_take = 0;
  std::vector<int> marker_frames;  // spatial markers: montage frames
};

// The montage scene (table frame, converted to glTF's +Y up):
//   "montage" row: each object's montage node and its spatial markers (grey static copies of the
//     object at the marked montage frames, the paper's Figure 5);
//   "take K warped" (K from 1): each object's take K on the reference timeline (w_K(t));
//   "take K recorded": each object's take K as recorded.
// Rows and columns are offset along glTF x (columns: montage, take 1, ...) and z (warped in front
// of recorded) by a spacing derived from the trajectories' extent, so that nothing overlaps. One
// animation "montage" plays every node together, each from time 0 (its track's time origin is its
// first timestamp). Layered objects are separate nodes in every row. InputError for an object
// without takes, warps of the wrong size or markers past the montage's end.
GltfScene MontageScene(const std::vector<MontageObject>& objects);

}  // namespace mmh::report
