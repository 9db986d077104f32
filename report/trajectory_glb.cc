#include "report/trajectory_glb.h"

#include <algorithm>

#include "core/error.h"
#include "sim/primitives.h"
#include "sim/render_session.h"

namespace mmh::report {
namespace {

// Maps every pose of a trajectory given in `frame` into glTF's axes.
Trajectory ToGltf(const Trajectory& frame_T_proxy, TrajectoryFrame frame) {
  const Rigid3 gltf_T_frame = GltfTFrame(frame);
  Trajectory gltf_T_proxy;
  gltf_T_proxy.timestamps = frame_T_proxy.timestamps;
  gltf_T_proxy.poses.reserve(frame_T_proxy.size());
  for (const Rigid3& pose : frame_T_proxy.poses) gltf_T_proxy.poses.push_back(gltf_T_frame * pose);
  return gltf_T_proxy;
}

GltfNode Node(std::string name, int mesh, NodeLook look = NodeLook::kColored,
              const Rigid3& parent_T_node = Rigid3::Identity()) {
  GltfNode node;
  node.name = std::move(name);
  node.mesh = mesh;
  node.look = look;
  node.parent_T_node = parent_T_node;
  return node;
}

int AddNode(GltfScene* scene, GltfNode node) {
  scene->nodes.push_back(std::move(node));
  return static_cast<int>(scene->nodes.size()) - 1;
}

void AddTrack(GltfScene* scene, int node, const Trajectory& table_T_proxy) {
  GltfTrack track;
  track.node = node;
  track.parent_T_node = ToGltf(table_T_proxy, TrajectoryFrame::kTable);
  track.time_origin = table_T_proxy.timestamps.front();
  scene->nodes[node].parent_T_node = track.parent_T_node.poses.front();
  scene->animations.front().tracks.push_back(std::move(track));
}

}  // namespace

TriangleMesh LoadExportMesh(const std::filesystem::path& path, double scale) {
  if (path.empty()) ThrowBadValue("--model", "an empty path", "a .json, .obj or .ply file");
  TriangleMesh mesh = sim::LoadProxyModel(path.string(), scale);
  ValidateMesh(mesh, path.string());
  return mesh;
}

TriangleMesh OrientedStandIn() {
  constexpr Rgb8 kBody = {200, 200, 200};
  TriangleMesh mesh = sim::MakeBoxBetween({-0.03, -0.02, 0.0}, {0.03, 0.02, 0.03}, kBody);
  AppendMesh(sim::MakeBoxBetween({0.03, -0.004, 0.011}, {0.06, 0.004, 0.019}, {220, 30, 30}),
             Rigid3::Identity(), &mesh);
  AppendMesh(sim::MakeBoxBetween({-0.004, 0.02, 0.011}, {0.004, 0.05, 0.019}, {30, 170, 40}),
             Rigid3::Identity(), &mesh);
  AppendMesh(sim::MakeBoxBetween({-0.004, -0.004, 0.03}, {0.004, 0.004, 0.06}, {30, 60, 220}),
             Rigid3::Identity(), &mesh);
  return mesh;
}

GltfScene TrajectoryScene(const TriangleMesh& mesh, const Trajectory& frame_T_proxy,
                          const TrajectoryExportOptions& options) {
  ValidateTrajectory(frame_T_proxy, options.name);
  if (frame_T_proxy.empty()) ThrowBadValue(options.name, "no poses", "at least one pose");
  GltfScene scene;
  scene.meshes.push_back(mesh);
  scene.mesh_names.push_back(options.name);
  GltfTrack track;
  track.parent_T_node = ToGltf(frame_T_proxy, options.frame);
  track.time_origin = frame_T_proxy.timestamps.front();
  track.node = AddNode(&scene, Node(options.name, 0, NodeLook::kColored,
                                    track.parent_T_node.poses.front()));
  scene.roots.push_back(track.node);
  scene.animations.push_back({options.name, {std::move(track)}});
  return scene;
}

GltfScene MontageScene(const std::vector<MontageObject>& objects) {
  if (objects.empty()) ThrowBadValue("montage scene", "no objects", "at least one object");
  std::size_t take_count = 0;
  // Spacing: the largest horizontal extent of any trajectory plus the largest mesh, times 1.2.
  double extent = 0.0, mesh_size = 0.0;
  for (const MontageObject& object : objects) {
    const std::string where = "montage scene object " + object.name;
    ValidateTrajectory(object.montage, where + " montage");
    if (object.montage.empty()) ThrowBadValue(where + " montage", "no poses", "at least one pose");
    if (object.takes.empty()) ThrowBadValue(where, "no takes", "at least one take");
    if (object.warps.size() != object.takes.size()) {
      ThrowBadValue(where + " warps", std::to_string(object.warps.size()),
                    "one per take (" + std::to_string(object.takes.size()) + ")");
    }
    if (object.reference_take < 0 ||
        object.reference_take >= static_cast<int>(object.takes.size())) {
      ThrowBadValue(where + " reference_take", std::to_string(object.reference_take), "a take");
    }
    const std::size_t n = object.takes[object.reference_take].size();
    for (std::size_t k = 0; k < object.takes.size(); ++k) {
      ValidateTrajectory(object.takes[k], where + " take " + std::to_string(k + 1));
      if (object.warps[k].size() != n) {
        ThrowBadValue(where + " warp of take " + std::to_string(k + 1),
                      std::to_string(object.warps[k].size()) + " frames",
                      std::to_string(n) + " (the reference take's frames)");
      }
      for (int w : object.warps[k]) {
        if (w < 0 || w >= static_cast<int>(object.takes[k].size())) {
          ThrowBadValue(where + " warp of take " + std::to_string(k + 1), std::to_string(w),
                        "a frame of the take");
        }
      }
    }
    for (int frame : object.marker_frames) {
      if (frame < 0 || frame >= static_cast<int>(object.montage.size())) {
        ThrowBadValue(where + " spatial marker", std::to_string(frame),
                      "a frame of the montage (0.." + std::to_string(object.montage.size() - 1) + ")");
      }
    }
    take_count = std::max(take_count, object.takes.size());
    Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
    auto grow = [&](const Trajectory& t) {
      for (const Rigid3& p : t.poses) {
        lo = lo.cwiseMin(p.translation.head<2>());
        hi = hi.cwiseMax(p.translation.head<2>());
      }
    };
    grow(object.montage);
    for (const Trajectory& take : object.takes) grow(take);
    extent = std::max(extent, (hi - lo).maxCoeff());
    const Bounds3 bounds = ComputeBounds(object.mesh);
    mesh_size = std::max(mesh_size, (bounds.max - bounds.min).norm());
  }
  const double spacing = 1.2 * (extent + mesh_size);

  GltfScene scene;
  for (const MontageObject& object : objects) {
    scene.meshes.push_back(object.mesh);
    scene.mesh_names.push_back(object.name);
  }
  scene.animations.push_back({"montage", {}});
  auto add_group = [&](const std::string& name, const Eigen::Vector3d& gltf_offset) {
    const int group = AddNode(&scene, Node(name, -1, NodeLook::kColored,
                                           Rigid3(Eigen::Quaterniond::Identity(), gltf_offset)));
    scene.roots.push_back(group);
    return group;
  };
  auto add_child = [&](int group, GltfNode node) {
    const int index = AddNode(&scene, std::move(node));
    scene.nodes[group].children.push_back(index);
    return index;
  };

  const int montage_group = add_group("montage", Eigen::Vector3d::Zero());
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const MontageObject& object = objects[o];
    const int node = add_child(montage_group, Node(object.name + " montage", static_cast<int>(o)));
    AddTrack(&scene, node, object.montage);
    for (int frame : object.marker_frames) {
      add_child(montage_group, Node(object.name + " marker at frame " + std::to_string(frame),
                                    static_cast<int>(o), NodeLook::kGrey,
                                    GltfTFrame(TrajectoryFrame::kTable) * object.montage.poses[frame]));
    }
  }
  for (std::size_t k = 0; k < take_count; ++k) {
    const std::string take = "take " + std::to_string(k + 1);
    const double x = spacing * static_cast<double>(k + 1);
    const int warped_group = add_group(take + " warped", {x, 0.0, 0.0});
    const int recorded_group = add_group(take + " recorded", {x, 0.0, -spacing});
    for (std::size_t o = 0; o < objects.size(); ++o) {
      const MontageObject& object = objects[o];
      if (k >= object.takes.size()) continue;
      const Trajectory& reference = object.takes[object.reference_take];
      Trajectory warped;
      warped.timestamps = reference.timestamps;
      for (int w : object.warps[k]) warped.poses.push_back(object.takes[k].poses[w]);
      AddTrack(&scene, add_child(warped_group, Node(object.name + " " + take + " warped", static_cast<int>(o))),
               warped);
      AddTrack(&scene,
               add_child(recorded_group, Node(object.name + " " + take + " recorded", static_cast<int>(o))),
               object.takes[k]);
    }
  }
  return scene;
}

}  // namespace mmh::report
