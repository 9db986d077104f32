#include "report/gltf_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"

namespace mmh::report {
namespace {

using nlohmann::json;

// glTF's enums (specification, 5.1 and 5.11).
constexpr int kFloat = 5126;
constexpr int kArrayBuffer = 34962;
constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;
constexpr std::uint32_t kBinChunk = 0x004E4942;
// The grey of spatial markers (the paper's Figure 5 shows the marked poses as grey copies).
constexpr double kMarkerGrey = 0.45;
// Largest error of a 32-bit float keyframe time (s) before the exact times go to the extras.
constexpr double kExactTimeError = 5e-7;

// The binary chunk and the JSON entries describing it, one bufferView per accessor.
class BufferBuilder {
 public:
  explicit BufferBuilder(json* root) : root_(root) {}

  // Appends `count` elements of `components` floats; returns the accessor's index.
  int AddFloats(const std::vector<float>& values, int components, const char* type,
                bool vertex_attribute, bool with_bounds) {
    while (bytes_.size() % 4 != 0) bytes_.push_back(0);
    const std::size_t offset = bytes_.size();
    bytes_.resize(offset + values.size() * sizeof(float));
    std::memcpy(bytes_.data() + offset, values.data(), values.size() * sizeof(float));
    json view = {{"buffer", 0},
                 {"byteOffset", offset},
                 {"byteLength", values.size() * sizeof(float)}};
    if (vertex_attribute) view["target"] = kArrayBuffer;
    (*root_)["bufferViews"].push_back(view);
    const int count = static_cast<int>(values.size()) / components;
    json accessor = {{"bufferView", (*root_)["bufferViews"].size() - 1},
                     {"componentType", kFloat},
                     {"count", count},
                     {"type", type}};
    if (with_bounds) {
      std::vector<float> lo(values.begin(), values.begin() + components);
      std::vector<float> hi = lo;
      for (std::size_t i = 0; i < values.size(); ++i) {
        const std::size_t c = i % components;
        lo[c] = std::min(lo[c], values[i]);
        hi[c] = std::max(hi[c], values[i]);
      }
      accessor["min"] = lo;
      accessor["max"] = hi;
    }
    (*root_)["accessors"].push_back(accessor);
    return static_cast<int>((*root_)["accessors"].size()) - 1;
  }

  const std::string& bytes() const { return bytes_; }

 private:
  json* root_;
  std::string bytes_;
};

json PoseTrs(const Rigid3& parent_T_node) {
  json node;
  const Eigen::Quaterniond q = parent_T_node.rotation.normalized();
  if (!parent_T_node.translation.isZero(0.0)) {
    node["translation"] = {parent_T_node.translation.x(), parent_T_node.translation.y(),
                           parent_T_node.translation.z()};
  }
  if (q.vec().norm() > 0.0) node["rotation"] = {q.x(), q.y(), q.z(), q.w()};
  return node;
}

void CheckPose(const Rigid3& pose, const std::string& where) {
  if (!pose.translation.allFinite() || !pose.rotation.coeffs().allFinite()) {
    ThrowBadValue(where, "a non-finite pose", "finite translation and quaternion");
  }
  const double norm = pose.rotation.norm();
  if (std::abs(norm - 1.0) > 1e-6) {
    ThrowBadValue(where, "quaternion norm " + FormatNumber(norm), "a unit quaternion (to 1e-6)");
  }
}

void ValidateScene(const GltfScene& scene) {
  if (scene.mesh_names.size() != scene.meshes.size()) {
    ThrowBadValue("glTF scene", std::to_string(scene.mesh_names.size()) + " mesh names",
                  "one per mesh (" + std::to_string(scene.meshes.size()) + ")");
  }
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    ValidateMesh(scene.meshes[m], "glTF mesh " + scene.mesh_names[m]);
  }
  const int nodes = static_cast<int>(scene.nodes.size());
  std::vector<int> parents(nodes, 0);
  for (int root : scene.roots) {
    if (root < 0 || root >= nodes) ThrowBadValue("glTF scene root", std::to_string(root), "a node");
    ++parents[root];
  }
  for (const GltfNode& node : scene.nodes) {
    const std::string where = "glTF node " + node.name;
    if (node.mesh < -1 || node.mesh >= static_cast<int>(scene.meshes.size())) {
      ThrowBadValue(where + " mesh", std::to_string(node.mesh), "-1 or a mesh index");
    }
    CheckPose(node.parent_T_node, where);
    for (int child : node.children) {
      if (child < 0 || child >= nodes) ThrowBadValue(where + " child", std::to_string(child), "a node");
      ++parents[child];
    }
  }
  for (int i = 0; i < nodes; ++i) {
    if (parents[i] > 1) {
      ThrowBadValue("glTF node " + scene.nodes[i].name, std::to_string(parents[i]) + " parents",
                    "at most one parent (a tree)");
    }
  }
  for (const GltfAnimation& animation : scene.animations) {
    std::map<std::string, int> names;  // the extras' time origins are keyed by node name
    for (const GltfTrack& track : animation.tracks) {
      const std::string where = "glTF animation " + animation.name + " track of node " +
                                std::to_string(track.node);
      if (track.node < 0 || track.node >= nodes) ThrowBadValue(where, "node index", "a node");
      if (++names[scene.nodes[track.node].name] > 1) {
        ThrowBadValue(where, "node name " + scene.nodes[track.node].name + " animated twice",
                      "one track per node and unique names of animated nodes");
      }
      ValidateTrajectory(track.parent_T_node, where);
      for (std::size_t i = 0; i < track.parent_T_node.size(); ++i) {
        CheckPose(track.parent_T_node.poses[i], where + " frame " + std::to_string(i));
      }
      if (track.parent_T_node.timestamps.front() < track.time_origin) {
        ThrowBadValue(where, "first timestamp " + FormatNumber(track.parent_T_node.timestamps.front()),
                      "not before the time origin " + FormatNumber(track.time_origin));
      }
    }
  }
}

void AppendU32(std::string* out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

// The two materials: the blocks' vertex colours, and the spatial markers' grey.
json Materials() {
  return json::array(
      {{{"name", "block colours"},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}}, {"metallicFactor", 0.0},
          {"roughnessFactor", 0.8}}}},
       {{"name", "spatial marker"},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {kMarkerGrey, kMarkerGrey, kMarkerGrey, 1.0}},
          {"metallicFactor", 0.0},
          {"roughnessFactor", 0.9}}}}});
}

// The accessors of one source mesh's vertex data (-1: the mesh is used by no node).
struct MeshAccessors {
  int position = -1, normal = -1, color = -1;
};

// Vertex data per source mesh a node uses: three vertices per non-degenerate face, flat normals,
// linear colours. InputError for a used mesh with only degenerate faces.
std::vector<MeshAccessors> AddMeshData(const GltfScene& scene, BufferBuilder* buffer) {
  std::vector<MeshAccessors> accessors(scene.meshes.size());
  std::vector<bool> used(scene.meshes.size(), false);
  for (const GltfNode& node : scene.nodes) {
    if (node.mesh >= 0) used[node.mesh] = true;
  }
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    if (!used[m]) continue;
    const TriangleMesh& mesh = scene.meshes[m];
    const auto normals = FaceNormals(mesh);
    std::vector<float> positions, vertex_normals, colors;
    for (int f = 0; f < mesh.face_count(); ++f) {
      if (normals.row(f).squaredNorm() == 0.0f) continue;  // degenerate: no area, no normal
      for (int k = 0; k < 3; ++k) {
        const auto v = mesh.vertices.row(mesh.faces(f, k));
        for (int c = 0; c < 3; ++c) {
          positions.push_back(v(c));
          vertex_normals.push_back(normals(f, c));
          colors.push_back(static_cast<float>(SrgbToLinear(mesh.face_colors(f, c))));
        }
      }
    }
    if (positions.empty()) {
      ThrowBadValue("glTF mesh " + scene.mesh_names[m], "only degenerate faces",
                    "at least one face with an area");
    }
    accessors[m].position = buffer->AddFloats(positions, 3, "VEC3", true, true);
    accessors[m].normal = buffer->AddFloats(vertex_normals, 3, "VEC3", true, false);
    accessors[m].color = buffer->AddFloats(colors, 3, "VEC3", true, false);
  }
  return accessors;
}

// root["nodes"] and root["meshes"]: one glTF mesh per (mesh, look) pair in use, the looks sharing
// the vertex accessors; the marker material is dropped when no node is grey (unused objects are
// the validator's infos).
void AddNodesAndMeshes(const GltfScene& scene, const std::vector<MeshAccessors>& accessors,
                       json* root) {
  std::map<std::pair<int, NodeLook>, int> gltf_meshes;
  (*root)["meshes"] = json::array();
  (*root)["nodes"] = json::array();
  for (const GltfNode& node : scene.nodes) {
    json out = PoseTrs(node.parent_T_node);
    out["name"] = node.name;
    if (!node.children.empty()) out["children"] = node.children;
    if (node.mesh >= 0) {
      const auto key = std::make_pair(node.mesh, node.look);
      auto it = gltf_meshes.find(key);
      if (it == gltf_meshes.end()) {
        const MeshAccessors& a = accessors[node.mesh];
        json attributes = {{"POSITION", a.position}, {"NORMAL", a.normal}};
        if (node.look == NodeLook::kColored) attributes["COLOR_0"] = a.color;
        const bool grey = node.look == NodeLook::kGrey;
        (*root)["meshes"].push_back(
            {{"name", scene.mesh_names[node.mesh] + (grey ? " (marker)" : "")},
             {"primitives", {{{"attributes", attributes}, {"material", grey ? 1 : 0}}}}});
        it = gltf_meshes.emplace(key, static_cast<int>((*root)["meshes"].size()) - 1).first;
      }
      out["mesh"] = it->second;
    }
    (*root)["nodes"].push_back(out);
  }
  if ((*root)["meshes"].empty()) root->erase("meshes");
  const bool any_grey = std::any_of(scene.nodes.begin(), scene.nodes.end(), [](const GltfNode& n) {
    return n.mesh >= 0 && n.look == NodeLook::kGrey;
  });
  if (!any_grey) (*root)["materials"].erase(1);
}

// A track's keyframes as glTF stores them: float32 times after the origin, translations, and
// rotations (x y z w, signs chosen so that consecutive quaternions interpolate the short way).
struct TrackSamples {
  std::vector<float> times, translations, rotations;
  double max_time_error = 0.0;  // [s], the float32 times against the exact ones
};

TrackSamples SampleTrack(const GltfScene& scene, const GltfAnimation& animation,
                         const GltfTrack& track) {
  const Trajectory& poses = track.parent_T_node;
  TrackSamples samples;
  Eigen::Quaterniond previous = poses.poses.front().rotation;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const float time = static_cast<float>(poses.timestamps[i] - track.time_origin);
    if (!samples.times.empty() && !(time > samples.times.back())) {
      ThrowBadValue("glTF animation " + animation.name + " node " + scene.nodes[track.node].name +
                        " frame " + std::to_string(i),
                    "timestamp " + FormatNumber(poses.timestamps[i]),
                    "times that stay strictly increasing as 32-bit floats after subtracting " +
                        FormatNumber(track.time_origin) + " s");
    }
    samples.times.push_back(time);
    samples.max_time_error =
        std::max(samples.max_time_error,
                 std::abs(double(time) - (poses.timestamps[i] - track.time_origin)));
    Eigen::Quaterniond q = poses.poses[i].rotation.normalized();
    if (q.coeffs().dot(previous.coeffs()) < 0.0) q.coeffs() = -q.coeffs();
    previous = q;
    for (int c = 0; c < 3; ++c) {
      samples.translations.push_back(static_cast<float>(poses.poses[i].translation(c)));
    }
    for (int c = 0; c < 4; ++c) samples.rotations.push_back(static_cast<float>(q.coeffs()(c)));
  }
  return samples;
}

// The input accessor must be 32-bit floats (glTF 2.0, "Animations"): half a unit in the last place
// is 4.8e-7 s below 16 s, 9.5e-7 s from 16 s on, 3.8e-6 s at 100 s. Beyond 5e-7 s the exact times
// go to the animation's extras too: the frame period of an evenly sampled track (timestamps
// origin + i * period to 5e-7 s), else every time after the origin (JSON doubles).
void AddExactTimes(const std::string& name, const GltfTrack& track, json* extras) {
  const Trajectory& poses = track.parent_T_node;
  const double period = poses.size() > 1 ? (poses.timestamps.back() - poses.timestamps.front()) /
                                               static_cast<double>(poses.size() - 1)
                                         : 0.0;
  bool even = poses.size() > 1;
  for (std::size_t i = 0; i < poses.size() && even; ++i) {
    even = std::abs(poses.timestamps.front() + double(i) * period - poses.timestamps[i]) <=
           kExactTimeError;
  }
  if (even && poses.timestamps.front() == track.time_origin) {
    (*extras)["mmh_frame_periods_s"][name] = period;
  } else {
    json exact = json::array();
    for (double t : poses.timestamps) exact.push_back(t - track.time_origin);
    (*extras)["mmh_times_s"][name] = exact;
  }
}

// One animation: per track one time accessor shared by a translation and a rotation sampler.
json AnimationJson(const GltfScene& scene, const GltfAnimation& animation,
                   BufferBuilder* buffer) {
  json out = {{"name", animation.name},
              {"samplers", json::array()},
              {"channels", json::array()},
              {"extras", {{"mmh_time_origins_s", json::object()}}}};
  for (const GltfTrack& track : animation.tracks) {
    const std::string& name = scene.nodes[track.node].name;
    out["extras"]["mmh_time_origins_s"][name] = track.time_origin;
    const TrackSamples samples = SampleTrack(scene, animation, track);
    if (samples.max_time_error > kExactTimeError) AddExactTimes(name, track, &out["extras"]);
    const int input = buffer->AddFloats(samples.times, 1, "SCALAR", false, true);
    const int translation = buffer->AddFloats(samples.translations, 3, "VEC3", false, false);
    const int rotation = buffer->AddFloats(samples.rotations, 4, "VEC4", false, false);
    const int first = static_cast<int>(out["samplers"].size());
    out["samplers"].push_back(
        {{"input", input}, {"output", translation}, {"interpolation", "LINEAR"}});
    out["samplers"].push_back({{"input", input}, {"output", rotation}, {"interpolation", "LINEAR"}});
    out["channels"].push_back(
        {{"sampler", first}, {"target", {{"node", track.node}, {"path", "translation"}}}});
    out["channels"].push_back(
        {{"sampler", first + 1}, {"target", {{"node", track.node}, {"path", "rotation"}}}});
  }
  return out;
}

// The binary glTF container (glTF 2.0, "GLB File Format Specification"): a 12-byte header, the
// JSON chunk padded with spaces and the binary chunk padded with zeros to 4 bytes.
std::string GlbContainer(json root, std::string bin) {
  while (bin.size() % 4 != 0) bin.push_back('\0');
  if (!bin.empty()) root["buffers"] = json::array({{{"byteLength", bin.size()}}});
  else root.erase("bufferViews"), root.erase("accessors");
  std::string text = root.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  std::string glb;
  const std::size_t total = 12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size());
  AppendU32(&glb, kGlbMagic);
  AppendU32(&glb, 2);
  AppendU32(&glb, static_cast<std::uint32_t>(total));
  AppendU32(&glb, static_cast<std::uint32_t>(text.size()));
  AppendU32(&glb, kJsonChunk);
  glb += text;
  if (!bin.empty()) {
    AppendU32(&glb, static_cast<std::uint32_t>(bin.size()));
    AppendU32(&glb, kBinChunk);
    glb += bin;
  }
  return glb;
}

}  // namespace

Rigid3 GltfTFrame(TrajectoryFrame frame) {
  if (frame == TrajectoryFrame::kTable) {
    // (x, y, z) -> (x, z, -y): -90 deg about x.
    return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())),
                  Eigen::Vector3d::Zero());
  }
  // (x, y, z) -> (x, -y, -z): 180 deg about x.
  return Rigid3(Eigen::Quaterniond(0.0, 1.0, 0.0, 0.0), Eigen::Vector3d::Zero());
}

double SrgbToLinear(std::uint8_t value) {
  const double c = value / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

std::string EncodeGlb(const GltfScene& scene) {
  ValidateScene(scene);
  json root;
  root["asset"] = {{"version", "2.0"}, {"generator", "mmh (MotionMontage harness)"}};
  root["bufferViews"] = json::array();
  root["accessors"] = json::array();
  root["materials"] = Materials();
  BufferBuilder buffer(&root);
  AddNodesAndMeshes(scene, AddMeshData(scene, &buffer), &root);
  for (const GltfAnimation& animation : scene.animations) {
    json out = AnimationJson(scene, animation, &buffer);
    if (!out["channels"].empty()) root["animations"].push_back(out);
  }
  root["scene"] = 0;
  root["scenes"] = json::array({{{"nodes", scene.roots}}});
  return GlbContainer(std::move(root), buffer.bytes());
}

void WriteGlb(const std::filesystem::path& path, const GltfScene& scene) {
  WriteFileAtomically(path, EncodeGlb(scene));
}

}  // namespace mmh::report
