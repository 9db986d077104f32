// glTF 2.0 binary (.glb) files of our own (the Khronos specification, version 2.0): meshes with
// flat normals and per-face colours, nodes, and animations with one keyframe per frame
// (translation and rotation channels, LINEAR interpolation, times in seconds).
//
// Frames: glTF is +Y up, metres, right-handed. Our table frame is +Z up, so a node's pose is
// gltf_T_proxy = kGltfTTable * table_T_proxy with kGltfTTable the rotation by -90 deg about x:
// (x, y, z)_table -> (x, z, -y)_gltf (docs/notation.md, "glTF export").
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/rigid3.h"
#include "core/trajectory.h"
#include "core/triangle_mesh.h"

namespace mmh::report {

// The frame a trajectory's poses are given in (its parent in the glTF scene).
enum class TrajectoryFrame {
  kTable,   // table_T_proxy: z up (the harness's default for takes and montages)
  kCamera,  // camera_T_proxy of the Kinect: x right, y down, z forward
};

// gltf_T_frame: maps `frame` coordinates into glTF's (+Y up; for the camera, glTF's camera
// convention: looking down -Z with +Y up).
Rigid3 GltfTFrame(TrajectoryFrame frame);

// How a node's mesh is drawn.
enum class NodeLook {
  kColored,  // the mesh's per-face colours
  kGrey,     // one grey material (spatial markers, the paper's Figure 5)
};

struct GltfNode {
  std::string name;
  int mesh = -1;  // index into GltfScene::meshes, -1 for a group node
  NodeLook look = NodeLook::kColored;
  Rigid3 parent_T_node;       // rest pose (glTF frame); animated nodes start at their first key
  std::vector<int> children;  // node indices
};

// One animated node: gltf_T_node at each timestamp (parent frame = glTF's axes).
struct GltfTrack {
  int node = 0;
  Trajectory parent_T_node;  // timestamps in seconds
  // Subtracted from every timestamp (glTF times start near 0 and are 32-bit floats: a TUM
  // timestamp of 1.3e9 s would lose its frames). Written to the animation's extras
  // ("mmh_time_origins_s": node name -> origin), so that a reader gets the timestamps back.
  // Where 32-bit float times are off by more than 5e-7 s (from 16 s after the origin on; 1e-6 s
  // is passed at 16.8 s, 3.8e-6 s at 100 s), the extras also hold the exact times:
  // "mmh_frame_periods_s" (node -> period: timestamp i = origin + i * period to 5e-7 s, for
  // evenly sampled tracks starting at the origin) or else "mmh_times_s" (node -> every
  // timestamp - origin).
  double time_origin = 0.0;
};

// All tracks of an animation play together (a viewer plays one animation at a time).
struct GltfAnimation {
  std::string name;
  std::vector<GltfTrack> tracks;
};

struct GltfScene {
  std::vector<TriangleMesh> meshes;
  std::vector<std::string> mesh_names;  // one per mesh
  std::vector<GltfNode> nodes;
  std::vector<int> roots;  // nodes of the scene
  std::vector<GltfAnimation> animations;
};

// The .glb bytes. The scene is checked first (InputError naming the node, track or mesh: indices
// in range, every node at most one parent, valid meshes, finite poses with unit quaternions,
// strictly increasing timestamps not before the track's time origin). Rotation keys keep the hemisphere
// of the previous key (q and -q are one rotation) so that component-wise interpolators (Blender's
// f-curves) never swing the long way round.
std::string EncodeGlb(const GltfScene& scene);

// Writes EncodeGlb(scene) atomically.
void WriteGlb(const std::filesystem::path& path, const GltfScene& scene);

// Linear-light value of an 8-bit sRGB channel (glTF's COLOR_0 and base colours are linear).
double SrgbToLinear(std::uint8_t value);

}  // namespace mmh::report
