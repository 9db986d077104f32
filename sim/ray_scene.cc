#include "sim/ray_scene.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "core/error.h"
#include "core/simd.h"
#include "sim/embree_config.h"

namespace mmh::sim {
namespace {

constexpr int kTile = HitPacket::kTile;  // 4x4 pixels per 16-ray packet

const char* ErrorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN:
      return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION:
      return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED:
      return "RTC_ERROR_CANCELLED";
  }
  return "RTC_ERROR_?";
}

// Column-major 3x4 affine matrix of a rigid transform, as Embree takes it.
void ToEmbreeTransform(const Rigid3& a_T_b, float out[12]) {
  const Eigen::Matrix3d r = a_T_b.rotation.normalized().toRotationMatrix();
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) out[c * 3 + row] = static_cast<float>(r(row, c));
  }
  for (int row = 0; row < 3; ++row) out[9 + row] = static_cast<float>(a_T_b.translation[row]);
}

// Directions of a 4x4 tile's rays: column part of the tile's columns plus row part of its rows
// (per component; `columns` and `rows` point at the tile's first column and row).
inline void TileDirections(const float* __restrict columns, const float* __restrict rows,
                           float* __restrict out) {
  for (int r = 0; r < kTile; ++r) {
    for (int c = 0; c < kTile; ++c) out[r * kTile + c] = columns[c] + rows[r];
  }
}

// Unit normals facing the camera and incidence cosines of 16 lanes (lanes without a hit compute
// values nobody reads; no traps).
inline void FinishLanes(const float* __restrict nx_in, const float* __restrict ny_in,
                        const float* __restrict nz_in, const float* __restrict dx_in,
                        const float* __restrict dy_in, const float* __restrict dz_in,
                        const float* __restrict tfar, HitPacket* __restrict out) {
  for (int i = 0; i < HitPacket::kLanes; ++i) {
    const float nx = nx_in[i], ny = ny_in[i], nz = nz_in[i];
    const float dx = dx_in[i], dy = dy_in[i], dz = dz_in[i];
    const float normal_norm = std::sqrt(nx * nx + ny * ny + nz * nz);
    const float norms = normal_norm * std::sqrt(dx * dx + dy * dy + dz * dz);
    const float dot = nx * dx + ny * dy + nz * dz;
    // Face the camera: the sensor sees the side the ray hits.
    const float sign = dot > 0 ? -1.0f : 1.0f;
    const float scale = normal_norm > 0 ? sign / (normal_norm > 0 ? normal_norm : 1.0f) : 1.0f;
    out->normal_x[i] = nx * scale;
    out->normal_y[i] = ny * scale;
    out->normal_z[i] = nz * scale;
    out->depth[i] = tfar[i];
    const float ratio = std::abs(dot) / (norms > 0 ? norms : 1.0f);
    out->cos_incidence[i] = norms > 0 ? (ratio < 1.0f ? ratio : 1.0f) : 0.0f;
  }
}

// Normals of a packet from an object's frame to the world.
inline void RotateNormals(const Eigen::Matrix3f& world_R_frame, HitPacket* __restrict out) {
  float r[9];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r[3 * row + col] = world_R_frame(row, col);
  }
  for (int i = 0; i < HitPacket::kLanes; ++i) {
    const float x = out->normal_x[i], y = out->normal_y[i], z = out->normal_z[i];
    out->normal_x[i] = r[0] * x + r[1] * y + r[2] * z;
    out->normal_y[i] = r[3] * x + r[4] * y + r[5] * z;
    out->normal_z[i] = r[6] * x + r[7] * y + r[8] * z;
  }
}

}  // namespace

void HitBuffer::Resize(int pixel_count) {
  depth.assign(pixel_count, std::numeric_limits<float>::infinity());
  object.assign(pixel_count, kNoObject);
  face.assign(pixel_count, 0);
  cos_incidence.assign(pixel_count, 0.0f);
  normal.assign(3 * static_cast<size_t>(pixel_count), 0.0f);
}

std::vector<PixelSpan> FullImageSpans(const PinholeIntrinsics& intrinsics) {
  std::vector<PixelSpan> spans;
  spans.reserve(intrinsics.height);
  for (int v = 0; v < intrinsics.height; ++v) spans.push_back({v, 0, intrinsics.width - 1});
  return spans;
}

struct RayScene::Impl {
  struct Object {
    std::string name;
    SurfaceMaterial material;
    TriangleMesh mesh;
    bool moving = false;
    bool visible = true;
    Rigid3 world_T_object;
    // Moving objects: their own scene and one instance in each top-level scene.
    RTCScene scene = nullptr;
    unsigned full_instance = RTC_INVALID_GEOMETRY_ID;
    unsigned moving_instance = RTC_INVALID_GEOMETRY_ID;
    bool dirty = true;
  };

  RTCDevice device = nullptr;
  // Embree has no native 16-ray kernels on this CPU (no AVX-512) but 8-ray ones (TileCast).
  bool split_packets = false;
  RTCScene static_scene = nullptr;  // static meshes in world coordinates
  RTCScene full_scene = nullptr;    // static instance + moving instances
  RTCScene moving_scene = nullptr;  // moving instances only
  std::vector<Object> objects;
  std::vector<uint32_t> static_geometry_object;  // static scene geomID -> object
  std::vector<uint32_t> full_instance_object;    // full scene geomID -> object (or kNoObject)
  std::vector<uint32_t> moving_instance_object;  // moving scene geomID -> object
  bool static_built = false;
  mutable std::atomic<uint64_t> rays{0};

  std::mutex error_mutex;
  std::string error;

  // How a hit's object is found: the static scene's geometry, the instance of the full or moving
  // top-level scene, or one object cast on its own (CastObject).
  enum class Lookup { kStaticGeometry, kFullInstance, kMovingInstance, kFixed };
  // The camera rays of `spans` in the frame of `scene` (frame_T_camera); world_R_frame turns
  // kFixed hits' normals to the world frame. Checks nothing: the callers do.
  void CastRays(RTCScene scene, Lookup lookup, uint32_t fixed_object, const Rigid3& frame_T_camera,
                const Eigen::Matrix3f& world_R_frame, const PinholeIntrinsics& intrinsics,
                std::span<const PixelSpan> spans, const float* max_depth, HitSink* sink) const;

  static void OnError(void* user, RTCError code, const char* message) {
    auto* self = static_cast<Impl*>(user);
    std::lock_guard<std::mutex> lock(self->error_mutex);
    if (self->error.empty()) {
      self->error = std::string("Embree: ") + ErrorName(code) + ": " + (message ? message : "");
    }
  }
  // Throws the first error the callback recorded (Embree calls are C: the callback must not
  // throw through them).
  void Check() {
    std::string message;
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      message.swap(error);
    }
    if (!message.empty()) throw std::runtime_error(message);
  }

  RTCGeometry MakeTriangles(const TriangleMesh& mesh, const Rigid3& a_T_mesh) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.vertex_count()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.face_count()));
    Check();
    for (int i = 0; i < mesh.vertex_count(); ++i) {
      const Eigen::Vector3d p = a_T_mesh * mesh.vertices.row(i).transpose().cast<double>();
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = static_cast<float>(p[k]);
    }
    for (int f = 0; f < mesh.face_count(); ++f) {
      for (int k = 0; k < 3; ++k) indices[3 * f + k] = mesh.faces(f, k);
    }
    rtcCommitGeometry(geometry);
    Check();
    return geometry;
  }

  unsigned AttachInstance(RTCScene top, RTCScene child) {
    RTCGeometry instance = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(instance, child);
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(instance);
    const unsigned id = rtcAttachGeometry(top, instance);
    rtcReleaseGeometry(instance);
    Check();
    return id;
  }

  // Builds a scene's BVH on one thread (see the constructor).
  void CommitScene(RTCScene scene) {
    build_arena.execute([scene] { rtcCommitScene(scene); });
  }
  tbb::task_arena build_arena{1};

  RTCScene NewScene() {
    RTCScene scene = rtcNewScene(device);
    // Robust (watertight) traversal: no pixel may see through the crack between two triangles.
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    Check();
    return scene;
  }
};

RayScene::RayScene() : impl_(std::make_unique<Impl>()) {
  // Default threading: "threads=1" would make Embree install a process-wide
  // tbb::global_control(max_allowed_parallelism, 1), serialising every TBB loop of the process
  // (the sensor's, the compositor's, frame-parallel rendering). Builds run in a one-thread arena
  // instead (Commit): BVHs are then built the same way on every machine and thread count.
  impl_->device = rtcNewDevice(EmbreeDeviceConfig());
  if (impl_->device == nullptr) {
    throw std::runtime_error(std::string("Embree: cannot create a device: ") +
                             ErrorName(rtcGetDeviceError(nullptr)));
  }
  rtcSetDeviceErrorFunction(impl_->device, &Impl::OnError, impl_.get());
  impl_->split_packets =
      rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) == 0 &&
      rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
  impl_->static_scene = impl_->NewScene();
  impl_->full_scene = impl_->NewScene();
  impl_->moving_scene = impl_->NewScene();
  rtcSetSceneBuildQuality(impl_->full_scene, RTC_BUILD_QUALITY_LOW);
  rtcSetSceneBuildQuality(impl_->moving_scene, RTC_BUILD_QUALITY_LOW);
}

RayScene::~RayScene() {
  for (auto& object : impl_->objects) {
    if (object.scene != nullptr) rtcReleaseScene(object.scene);
  }
  rtcReleaseScene(impl_->moving_scene);
  rtcReleaseScene(impl_->full_scene);
  rtcReleaseScene(impl_->static_scene);
  rtcReleaseDevice(impl_->device);
}

uint32_t RayScene::AddStatic(const std::string& name, const TriangleMesh& mesh,
                             const Rigid3& world_T_mesh) {
  if (impl_->static_built) {
    throw std::logic_error("RayScene::AddStatic after the first Commit");
  }
  ValidateMesh(mesh, name);
  const auto index = static_cast<uint32_t>(impl_->objects.size());
  RTCGeometry geometry = impl_->MakeTriangles(mesh, world_T_mesh);
  const unsigned id = rtcAttachGeometry(impl_->static_scene, geometry);
  rtcReleaseGeometry(geometry);
  impl_->Check();
  if (impl_->static_geometry_object.size() <= id) impl_->static_geometry_object.resize(id + 1);
  impl_->static_geometry_object[id] = index;
  Impl::Object object;
  object.name = name;
  object.mesh = mesh;
  object.world_T_object = world_T_mesh;
  impl_->objects.push_back(std::move(object));
  return index;
}

uint32_t RayScene::AddMoving(const std::string& name, const TriangleMesh& mesh) {
  if (impl_->static_built) {
    throw std::logic_error("RayScene::AddMoving after the first Commit");
  }
  ValidateMesh(mesh, name);
  const auto index = static_cast<uint32_t>(impl_->objects.size());
  Impl::Object object;
  object.name = name;
  object.mesh = mesh;
  object.moving = true;
  object.scene = impl_->NewScene();
  RTCGeometry geometry = impl_->MakeTriangles(mesh, Rigid3::Identity());
  rtcAttachGeometry(object.scene, geometry);
  rtcReleaseGeometry(geometry);
  impl_->CommitScene(object.scene);
  impl_->Check();
  object.full_instance = impl_->AttachInstance(impl_->full_scene, object.scene);
  object.moving_instance = impl_->AttachInstance(impl_->moving_scene, object.scene);
  auto record = [index](std::vector<uint32_t>& table, unsigned id) {
    if (table.size() <= id) table.resize(id + 1, kNoObject);
    table[id] = index;
  };
  record(impl_->full_instance_object, object.full_instance);
  record(impl_->moving_instance_object, object.moving_instance);
  impl_->objects.push_back(std::move(object));
  return index;
}

void RayScene::SetPose(uint32_t object, const Rigid3& world_T_object) {
  auto& o = impl_->objects.at(object);
  if (!o.moving) throw std::logic_error("RayScene::SetPose on the static object " + o.name);
  if (!world_T_object.translation.allFinite() || !world_T_object.rotation.coeffs().allFinite() ||
      std::abs(world_T_object.rotation.norm() - 1.0) > 1e-6) {
    ThrowBadValue("pose of " + o.name,
                  "t = (" + FormatNumber(world_T_object.translation.x()) + ", " +
                      FormatNumber(world_T_object.translation.y()) + ", " +
                      FormatNumber(world_T_object.translation.z()) +
                      "), |q| = " + FormatNumber(world_T_object.rotation.norm()),
                  "a finite translation and a unit quaternion");
  }
  o.world_T_object = world_T_object;
  o.dirty = true;
}

void RayScene::SetVisible(uint32_t object, bool visible) {
  auto& o = impl_->objects.at(object);
  if (!o.moving) throw std::logic_error("RayScene::SetVisible on the static object " + o.name);
  if (o.visible != visible) o.dirty = true;
  o.visible = visible;
}

void RayScene::Commit() {
  Impl& s = *impl_;
  if (!s.static_built) {
    s.CommitScene(s.static_scene);
    s.Check();
    const unsigned id = s.AttachInstance(s.full_scene, s.static_scene);
    if (s.full_instance_object.size() <= id) s.full_instance_object.resize(id + 1, kNoObject);
    s.full_instance_object[id] = kNoObject;  // the static instance: resolve by geomID
    s.static_built = true;
  }
  for (auto& o : s.objects) {
    if (!o.moving || !o.dirty) continue;
    float transform[12];
    ToEmbreeTransform(o.world_T_object, transform);
    for (RTCScene top : {s.full_scene, s.moving_scene}) {
      RTCGeometry instance =
          rtcGetGeometry(top, top == s.full_scene ? o.full_instance : o.moving_instance);
      rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, transform);
      if (o.visible) {
        rtcEnableGeometry(instance);
      } else {
        rtcDisableGeometry(instance);
      }
      rtcCommitGeometry(instance);
    }
    o.dirty = false;
  }
  s.CommitScene(s.full_scene);
  s.CommitScene(s.moving_scene);
  s.Check();
}

void RayScene::SetMaterial(uint32_t object, const SurfaceMaterial& material) {
  impl_->objects.at(object).material = material;
}
const SurfaceMaterial& RayScene::material(uint32_t object) const {
  return impl_->objects.at(object).material;
}

int RayScene::object_count() const { return static_cast<int>(impl_->objects.size()); }
const std::string& RayScene::object_name(uint32_t object) const {
  return impl_->objects.at(object).name;
}
const TriangleMesh& RayScene::object_mesh(uint32_t object) const {
  return impl_->objects.at(object).mesh;
}
bool RayScene::is_moving(uint32_t object) const { return impl_->objects.at(object).moving; }
const Rigid3& RayScene::world_T_object(uint32_t object) const {
  return impl_->objects.at(object).world_T_object;
}
uint64_t RayScene::rays_cast() const { return impl_->rays.load(); }

Bounds3 RayScene::WorldBounds(uint32_t object) const {
  const auto& o = impl_->objects.at(object);
  Bounds3 bounds;
  if (!o.visible) return bounds;
  const Bounds3 local = ComputeBounds(o.mesh);
  if (local.empty()) return bounds;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p((corner & 1) ? local.max.x() : local.min.x(),
                            (corner & 2) ? local.max.y() : local.min.y(),
                            (corner & 4) ? local.max.z() : local.min.z());
    const Eigen::Vector3d w = o.world_T_object * p;
    bounds.min = bounds.min.cwiseMin(w);
    bounds.max = bounds.max.cwiseMax(w);
  }
  return bounds;
}

namespace {

// Writes packets into a HitBuffer (the buffer's own depth bounds kMoving rays).
class HitBufferSink final : public HitSink {
 public:
  HitBufferSink(HitBuffer* hits, int width, bool write_misses)
      : hits_(hits), width_(width), write_misses_(write_misses) {}
  void Consume(const HitPacket& packet) override {
    for (int i = 0; i < HitPacket::kLanes; ++i) {
      if (!((packet.cast >> i) & 1u)) continue;
      const int u = packet.u0 + i % HitPacket::kTile;
      const int v = packet.v0 + i / HitPacket::kTile;
      const size_t p = static_cast<size_t>(v) * width_ + u;
      if (!((packet.hit >> i) & 1u)) {
        if (write_misses_) {
          hits_->depth[p] = std::numeric_limits<float>::infinity();
          hits_->object[p] = kNoObject;
          hits_->face[p] = 0;
          hits_->cos_incidence[p] = 0.0f;
        }
        continue;
      }
      hits_->depth[p] = packet.depth[i];
      hits_->object[p] = packet.object[i];
      hits_->face[p] = packet.face[i];
      hits_->cos_incidence[p] = packet.cos_incidence[i];
      hits_->normal[3 * p] = packet.normal_x[i];
      hits_->normal[3 * p + 1] = packet.normal_y[i];
      hits_->normal[3 * p + 2] = packet.normal_z[i];
    }
  }

 private:
  HitBuffer* hits_;
  int width_;
  bool write_misses_;
};

}  // namespace

void RayScene::Cast(const PinholeIntrinsics& intrinsics, const Rigid3& world_T_camera,
                    std::span<const PixelSpan> spans, Target target, HitBuffer* hits) const {
  if (static_cast<int>(hits->depth.size()) != intrinsics.width * intrinsics.height) {
    throw std::logic_error("RayScene::Cast: hit buffer of the wrong size");
  }
  HitBufferSink sink(hits, intrinsics.width, target != Target::kMoving);
  Cast(intrinsics, world_T_camera, spans, target,
       target == Target::kMoving ? hits->depth.data() : nullptr, &sink);
}

void RayScene::Cast(const PinholeIntrinsics& intrinsics, const Rigid3& world_T_camera,
                    std::span<const PixelSpan> spans, Target target, const float* max_depth,
                    HitSink* sink) const {
  const Impl& s = *impl_;
  if (!s.static_built) throw std::logic_error("RayScene::Cast before Commit");
  if (target == Target::kMoving && max_depth == nullptr) {
    throw std::logic_error("RayScene::Cast: kMoving needs the depth bound of every pixel");
  }
  const Impl::Lookup lookup = target == Target::kStatic ? Impl::Lookup::kStaticGeometry
                              : target == Target::kAll  ? Impl::Lookup::kFullInstance
                                                        : Impl::Lookup::kMovingInstance;
  RTCScene scene = target == Target::kAll      ? s.full_scene
                   : target == Target::kMoving ? s.moving_scene
                                               : s.static_scene;
  s.CastRays(scene, lookup, kNoObject, world_T_camera, Eigen::Matrix3f::Identity(), intrinsics,
             spans, target == Target::kMoving ? max_depth : nullptr, sink);
  impl_->Check();
}

void RayScene::CastObject(uint32_t object, const PinholeIntrinsics& intrinsics,
                          const Rigid3& world_T_camera, std::span<const PixelSpan> spans,
                          const float* max_depth, HitSink* sink) const {
  const Impl& s = *impl_;
  if (!s.static_built) throw std::logic_error("RayScene::CastObject before Commit");
  const Impl::Object& o = s.objects.at(object);
  if (!o.moving) throw std::logic_error("RayScene::CastObject on the static object " + o.name);
  if (max_depth == nullptr) {
    throw std::logic_error("RayScene::CastObject needs the depth bound of every pixel");
  }
  if (!o.visible) return;
  // The rays in the object's frame: rigid, so the ray parameter (the depth) is unchanged.
  const Rigid3 object_T_camera = o.world_T_object.Inverse() * world_T_camera;
  s.CastRays(o.scene, Impl::Lookup::kFixed, object, object_T_camera,
             o.world_T_object.rotation.normalized().toRotationMatrix().cast<float>(), intrinsics,
             spans, max_depth, sink);
  impl_->Check();
}

namespace {

// What the tiles of one CastRays call share (see there).
struct TileCast {
  enum Kind { kStatic, kInstanced, kFixed };
  RTCScene scene = nullptr;
  Kind kind = kStatic;
  uint32_t fixed_object = kNoObject;
  Eigen::Vector3f origin;
  Eigen::Matrix3f world_R_frame;
  const int* tiles = nullptr;  // indices into tile_mask
  const uint16_t* tile_mask = nullptr;
  int tx0 = 0, ty0 = 0, rect_width = 0, width = 0, padded_width = 0, padded_height = 0;
  const float* column_part = nullptr;  // 3 by padded_width
  const float* row_part = nullptr;     // 3 by padded_height
  const float* max_depth = nullptr;    // null: unbounded rays
  const uint32_t* instance_object = nullptr;
  const uint32_t* static_geometry_object = nullptr;
  const uint8_t* object_moving = nullptr;
  const Eigen::Matrix3f* world_R_object = nullptr;
  HitSink* sink = nullptr;
  // Cast each 16-ray packet as two 8-ray ones (RayScene::Impl::split_packets).
  bool split_packets = false;
};

// rtcIntersect16 without native 16-ray kernels: Embree's stream filter gathers the packet into
// two 8-ray packets (rays 0-7 and 8-15), every lane whose tnear <= tfar valid (all of ours: the
// lanes outside the tile's mask are traced too, their hits ignored), traces them with its 8-ray
// kernel and scatters the hits back. This does the same with plain copies instead of gathers
// and scatters: the same kernel on the same rays, so the same hits.
void IntersectAsTwoPackets(RTCScene scene, RTCIntersectContext* context, RTCRayHit16* packet) {
  alignas(32) static constexpr int kAll[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
  alignas(32) RTCRayHit8 half;
  for (int h = 0; h < 2; ++h) {
    const int o = 8 * h;
    RTCRay16& r = packet->ray;
    std::copy_n(r.org_x + o, 8, half.ray.org_x);
    std::copy_n(r.org_y + o, 8, half.ray.org_y);
    std::copy_n(r.org_z + o, 8, half.ray.org_z);
    std::copy_n(r.tnear + o, 8, half.ray.tnear);
    std::copy_n(r.dir_x + o, 8, half.ray.dir_x);
    std::copy_n(r.dir_y + o, 8, half.ray.dir_y);
    std::copy_n(r.dir_z + o, 8, half.ray.dir_z);
    std::copy_n(r.time + o, 8, half.ray.time);
    std::copy_n(r.tfar + o, 8, half.ray.tfar);
    std::copy_n(r.mask + o, 8, half.ray.mask);
    std::copy_n(r.id + o, 8, half.ray.id);
    std::copy_n(r.flags + o, 8, half.ray.flags);
    RTCHit16& hit = packet->hit;
    // (Lanes without a hit keep all their hit fields, as with the stream filter.)
    std::copy_n(hit.Ng_x + o, 8, half.hit.Ng_x);
    std::copy_n(hit.Ng_y + o, 8, half.hit.Ng_y);
    std::copy_n(hit.Ng_z + o, 8, half.hit.Ng_z);
    std::copy_n(hit.u + o, 8, half.hit.u);
    std::copy_n(hit.v + o, 8, half.hit.v);
    std::copy_n(hit.primID + o, 8, half.hit.primID);
    std::copy_n(hit.geomID + o, 8, half.hit.geomID);
    std::copy_n(hit.instID[0] + o, 8, half.hit.instID[0]);
    rtcIntersect8(kAll, scene, context, &half);
    std::copy_n(half.ray.tfar, 8, r.tfar + o);
    std::copy_n(half.hit.Ng_x, 8, hit.Ng_x + o);
    std::copy_n(half.hit.Ng_y, 8, hit.Ng_y + o);
    std::copy_n(half.hit.Ng_z, 8, hit.Ng_z + o);
    std::copy_n(half.hit.u, 8, hit.u + o);
    std::copy_n(half.hit.v, 8, hit.v + o);
    std::copy_n(half.hit.primID, 8, hit.primID + o);
    std::copy_n(half.hit.geomID, 8, hit.geomID + o);
    std::copy_n(half.hit.instID[0], 8, hit.instID[0] + o);
  }
}

// Casts tiles [first, last) of c.tiles and hands their packets to the sink; returns the number of
// rays. Cloned per x86-64 level (MMH_SIMD_CLONES) with the lane loops it inlines, so that they
// vectorise with no dispatch per packet.
MMH_SIMD_CLONES uint64_t CastTiles(const TileCast& c, size_t first, size_t last) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  uint64_t rays = 0;
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[16];
  HitPacket out;
  // Lane constants: Embree writes only tfar and the hit.
  for (int i = 0; i < 16; ++i) {
    packet.ray.org_x[i] = c.origin.x();
    packet.ray.org_y[i] = c.origin.y();
    packet.ray.org_z[i] = c.origin.z();
    packet.ray.tnear[i] = 0.0f;
    packet.ray.time[i] = 0.0f;
    packet.ray.mask[i] = 0xffffffffu;
    packet.ray.id[i] = i;
    packet.ray.flags[i] = 0;
  }
  alignas(64) float normal_x[16], normal_y[16], normal_z[16];
  for (size_t k = first; k != last; ++k) {
    const int tile = c.tiles[k];
    const int u0 = (c.tx0 + tile % c.rect_width) * kTile;
    const int v0 = (c.ty0 + tile / c.rect_width) * kTile;
    const uint16_t mask = c.tile_mask[tile];
    for (int i = 0; i < 16; ++i) {
      valid[i] = ((mask >> i) & 1u) ? -1 : 0;
      packet.ray.tfar[i] = std::numeric_limits<float>::infinity();
      packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    TileDirections(&c.column_part[u0], &c.row_part[v0], packet.ray.dir_x);
    TileDirections(&c.column_part[c.padded_width + u0], &c.row_part[c.padded_height + v0],
                   packet.ray.dir_y);
    TileDirections(&c.column_part[2 * c.padded_width + u0], &c.row_part[2 * c.padded_height + v0],
                   packet.ray.dir_z);
    if (c.max_depth != nullptr) {
      for (int i = 0; i < 16; ++i) {
        if ((mask >> i) & 1u) {
          packet.ray.tfar[i] =
              c.max_depth[static_cast<size_t>(v0 + i / kTile) * c.width + u0 + i % kTile];
        }
      }
    }
    rays += std::popcount(static_cast<unsigned>(mask));
    if (c.split_packets) {
      IntersectAsTwoPackets(c.scene, &context, &packet);
    } else {
      rtcIntersect16(valid, c.scene, &context, &packet);
    }
    out.u0 = u0;
    out.v0 = v0;
    out.cast = mask;
    uint32_t hit = 0;
    for (int i = 0; i < 16; ++i) {
      const bool lane_hit = valid[i] != 0 && packet.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
      hit |= static_cast<uint32_t>(lane_hit) << i;
    }
    out.hit = hit;
    const float* nx = packet.hit.Ng_x;
    const float* ny = packet.hit.Ng_y;
    const float* nz = packet.hit.Ng_z;
    if (c.kind == TileCast::kInstanced) {
      // Object-space normals of instances to world.
      std::copy_n(packet.hit.Ng_x, 16, normal_x);
      std::copy_n(packet.hit.Ng_y, 16, normal_y);
      std::copy_n(packet.hit.Ng_z, 16, normal_z);
      for (uint32_t bits = hit; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        uint32_t object = c.instance_object[packet.hit.instID[0][i]];
        if (object == kNoObject) object = c.static_geometry_object[packet.hit.geomID[i]];
        out.object[i] = object;
        if (!c.object_moving[object]) continue;
        const Eigen::Vector3f normal =
            c.world_R_object[object] *
            Eigen::Vector3f(packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i]);
        normal_x[i] = normal.x();
        normal_y[i] = normal.y();
        normal_z[i] = normal.z();
      }
      nx = normal_x;
      ny = normal_y;
      nz = normal_z;
    } else if (c.kind == TileCast::kFixed) {
      std::fill_n(out.object, 16, c.fixed_object);
    } else {
      for (uint32_t bits = hit; bits != 0; bits &= bits - 1) {
        const int i = std::countr_zero(bits);
        out.object[i] = c.static_geometry_object[packet.hit.geomID[i]];
      }
    }
    std::copy_n(packet.hit.primID, 16, out.face);
    FinishLanes(nx, ny, nz, packet.ray.dir_x, packet.ray.dir_y, packet.ray.dir_z, packet.ray.tfar,
                &out);
    if (c.kind == TileCast::kFixed) RotateNormals(c.world_R_frame, &out);
    c.sink->Consume(out);
  }
  return rays;
}

}  // namespace

void RayScene::Impl::CastRays(RTCScene scene, Lookup lookup, uint32_t fixed_object,
                              const Rigid3& frame_T_camera, const Eigen::Matrix3f& world_R_frame,
                              const PinholeIntrinsics& intrinsics, std::span<const PixelSpan> spans,
                              const float* max_depth, HitSink* sink) const {
  const Impl& s = *this;
  const int width = intrinsics.width;
  const int height = intrinsics.height;
  // 16-bit pixel masks of the 4x4 tiles touched by the spans, within the tile rectangle that
  // holds them (a few moving objects touch a small part of the image).
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  int tx0 = tiles_x, tx1 = -1, ty0 = tiles_y, ty1 = -1;
  for (const PixelSpan& span : spans) {
    const int first = std::max(span.first, 0);
    const int last = std::min(span.last, width - 1);
    if (span.row < 0 || span.row >= height || first > last) continue;
    tx0 = std::min(tx0, first / kTile);
    tx1 = std::max(tx1, last / kTile);
    ty0 = std::min(ty0, span.row / kTile);
    ty1 = std::max(ty1, span.row / kTile);
  }
  if (tx1 < tx0) return;
  const int rect_width = tx1 - tx0 + 1;
  std::vector<uint16_t> tile_mask(static_cast<size_t>(rect_width) * (ty1 - ty0 + 1), 0);
  for (const PixelSpan& span : spans) {
    const int first = std::max(span.first, 0);
    const int last = std::min(span.last, width - 1);
    if (span.row < 0 || span.row >= height || first > last) continue;
    uint16_t* row_masks = &tile_mask[static_cast<size_t>(span.row / kTile - ty0) * rect_width];
    const int shift = (span.row % kTile) * kTile;
    for (int t = first / kTile; t <= last / kTile; ++t) {
      const int a = std::max(first, t * kTile) - t * kTile;
      const int b = std::min(last, t * kTile + kTile - 1) - t * kTile;
      const unsigned bits = ((1u << (b + 1)) - 1u) & ~((1u << a) - 1u);
      row_masks[t - tx0] |= static_cast<uint16_t>(bits << shift);
    }
  }
  std::vector<int> tiles;  // indices into tile_mask
  tiles.reserve(tile_mask.size());
  for (int t = 0; t < static_cast<int>(tile_mask.size()); ++t) {
    if (tile_mask[t] != 0) tiles.push_back(t);
  }

  const Eigen::Matrix3f world_R_camera =
      frame_T_camera.rotation.normalized().toRotationMatrix().cast<float>();
  const Eigen::Vector3f origin = frame_T_camera.translation.cast<float>();
  const std::vector<uint32_t>& instance_object =
      lookup == Lookup::kMovingInstance ? s.moving_instance_object : s.full_instance_object;
  const bool instanced = lookup == Lookup::kFullInstance || lookup == Lookup::kMovingInstance;
  // World rotations of the moving objects, to bring Embree's object-space normals to world.
  std::vector<Eigen::Matrix3f> world_R_object(s.objects.size(), Eigen::Matrix3f::Identity());
  for (size_t i = 0; i < s.objects.size(); ++i) {
    if (s.objects[i].moving) {
      world_R_object[i] =
          s.objects[i].world_T_object.rotation.normalized().toRotationMatrix().cast<float>();
    }
  }

  // Ray directions are x_u * R.col(0) + y_v * R.col(1) + R.col(2) with x_u = (u - cx) / fx and
  // y_v = (v - cy) / fy: precomputed per column and row (padded to whole tiles), one addition per
  // component and ray.
  const int padded_width = tiles_x * kTile;
  const int padded_height = tiles_y * kTile;
  std::vector<float> column_part(3 * static_cast<size_t>(padded_width));
  std::vector<float> row_part(3 * static_cast<size_t>(padded_height));
  for (int u = 0; u < padded_width; ++u) {
    const Eigen::Vector3f c =
        world_R_camera.col(0) * static_cast<float>((u - intrinsics.cx) / intrinsics.fx);
    for (int k = 0; k < 3; ++k) column_part[k * padded_width + u] = c[k];
  }
  for (int v = 0; v < padded_height; ++v) {
    const Eigen::Vector3f r =
        world_R_camera.col(1) * static_cast<float>((v - intrinsics.cy) / intrinsics.fy) +
        world_R_camera.col(2);
    for (int k = 0; k < 3; ++k) row_part[k * padded_height + v] = r[k];
  }
  TileCast c;
  c.scene = scene;
  c.split_packets = s.split_packets;
  c.kind = lookup == Lookup::kFixed ? TileCast::kFixed
           : instanced              ? TileCast::kInstanced
                                    : TileCast::kStatic;
  c.fixed_object = fixed_object;
  c.origin = origin;
  c.world_R_frame = world_R_frame;
  c.tiles = tiles.data();
  c.tile_mask = tile_mask.data();
  c.tx0 = tx0;
  c.ty0 = ty0;
  c.rect_width = rect_width;
  c.width = width;
  c.padded_width = padded_width;
  c.padded_height = padded_height;
  c.column_part = column_part.data();
  c.row_part = row_part.data();
  c.max_depth = max_depth;
  c.instance_object = instance_object.data();
  c.static_geometry_object = s.static_geometry_object.data();
  std::vector<uint8_t> moving(s.objects.size());
  for (size_t i = 0; i < s.objects.size(); ++i) moving[i] = s.objects[i].moving;
  c.object_moving = moving.data();
  c.world_R_object = world_R_object.data();
  c.sink = sink;
  std::atomic<uint64_t> cast{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      cast.fetch_add(CastTiles(c, r.begin(), r.end()), std::memory_order_relaxed);
                    });
  rays.fetch_add(cast.load());
}

}  // namespace mmh::sim
