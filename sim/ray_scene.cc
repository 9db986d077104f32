#include "sim/ray_scene.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "core/error.h"

namespace mmh::sim {
namespace {

constexpr int kTile = 4;  // 4x4 pixels per 16-ray packet

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
  // One build thread: BVHs are then built the same way on every machine and thread count (the
  // scenes are small; building them is not where the time goes).
  impl_->device = rtcNewDevice("threads=1");
  if (impl_->device == nullptr) {
    throw std::runtime_error(std::string("Embree: cannot create a device: ") +
                             ErrorName(rtcGetDeviceError(nullptr)));
  }
  rtcSetDeviceErrorFunction(impl_->device, &Impl::OnError, impl_.get());
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
  rtcCommitScene(object.scene);
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
    rtcCommitScene(s.static_scene);
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
  rtcCommitScene(s.full_scene);
  rtcCommitScene(s.moving_scene);
  s.Check();
}

int RayScene::object_count() const { return static_cast<int>(impl_->objects.size()); }
const std::string& RayScene::object_name(uint32_t object) const {
  return impl_->objects.at(object).name;
}
const TriangleMesh& RayScene::object_mesh(uint32_t object) const {
  return impl_->objects.at(object).mesh;
}
bool RayScene::is_moving(uint32_t object) const { return impl_->objects.at(object).moving; }
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

void RayScene::Cast(const PinholeIntrinsics& intrinsics, const Rigid3& world_T_camera,
                    std::span<const PixelSpan> spans, Target target, HitBuffer* hits) const {
  const bool moving_only = target == Target::kMoving;
  const Impl& s = *impl_;
  if (!s.static_built) throw std::logic_error("RayScene::Cast before Commit");
  const int width = intrinsics.width;
  const int height = intrinsics.height;
  if (static_cast<int>(hits->depth.size()) != width * height) {
    throw std::logic_error("RayScene::Cast: hit buffer of the wrong size");
  }
  // 16-bit pixel masks of the 4x4 tiles touched by the spans.
  const int tiles_x = (width + kTile - 1) / kTile;
  const int tiles_y = (height + kTile - 1) / kTile;
  std::vector<uint16_t> tile_mask(static_cast<size_t>(tiles_x) * tiles_y, 0);
  for (const PixelSpan& span : spans) {
    if (span.row < 0 || span.row >= height) continue;
    const int first = std::max(span.first, 0);
    const int last = std::min(span.last, width - 1);
    for (int u = first; u <= last; ++u) {
      tile_mask[(span.row / kTile) * tiles_x + u / kTile] |=
          static_cast<uint16_t>(1u << ((span.row % kTile) * kTile + u % kTile));
    }
  }
  std::vector<int> tiles;
  for (int t = 0; t < static_cast<int>(tile_mask.size()); ++t) {
    if (tile_mask[t] != 0) tiles.push_back(t);
  }

  const Eigen::Matrix3f world_R_camera =
      world_T_camera.rotation.normalized().toRotationMatrix().cast<float>();
  const Eigen::Vector3f origin = world_T_camera.translation.cast<float>();
  RTCScene scene = target == Target::kAll      ? s.full_scene
                   : target == Target::kMoving ? s.moving_scene
                                               : s.static_scene;
  const std::vector<uint32_t>& instance_object =
      moving_only ? s.moving_instance_object : s.full_instance_object;
  const bool instanced = target != Target::kStatic;
  // World rotations of the moving objects, to bring Embree's object-space normals to world.
  std::vector<Eigen::Matrix3f> world_R_object(s.objects.size(), Eigen::Matrix3f::Identity());
  for (size_t i = 0; i < s.objects.size(); ++i) {
    if (s.objects[i].moving) {
      world_R_object[i] =
          s.objects[i].world_T_object.rotation.normalized().toRotationMatrix().cast<float>();
    }
  }

  // Ray directions are x_u * R.col(0) + y_v * R.col(1) + R.col(2) with x_u = (u - cx) / fx and
  // y_v = (v - cy) / fy: precomputed per column and row, three additions per ray.
  std::vector<Eigen::Vector3f> column_part(width), row_part(height);
  for (int u = 0; u < width; ++u) {
    column_part[u] =
        world_R_camera.col(0) * static_cast<float>((u - intrinsics.cx) / intrinsics.fx);
  }
  for (int v = 0; v < height; ++v) {
    row_part[v] = world_R_camera.col(1) * static_cast<float>((v - intrinsics.cy) / intrinsics.fy) +
                  world_R_camera.col(2);
  }
  std::atomic<uint64_t> cast{0};
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, tiles.size(), 32), [&](const tbb::blocked_range<size_t>& r) {
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        uint64_t local_rays = 0;
        alignas(64) RTCRayHit16 packet;
        alignas(64) int valid[16];
        for (size_t k = r.begin(); k != r.end(); ++k) {
          const int tile = tiles[k];
          const int u0 = (tile % tiles_x) * kTile;
          const int v0 = (tile / tiles_x) * kTile;
          const uint16_t mask = tile_mask[tile];
          for (int i = 0; i < 16; ++i) {
            const int u = u0 + i % kTile;
            const int v = v0 + i / kTile;
            const bool on = (mask >> i) & 1u;
            valid[i] = on ? -1 : 0;
            const bool inside = u < width && v < height;
            const Eigen::Vector3f dir = inside ? Eigen::Vector3f(column_part[u] + row_part[v])
                                               : Eigen::Vector3f(row_part[0]);
            packet.ray.org_x[i] = origin.x();
            packet.ray.org_y[i] = origin.y();
            packet.ray.org_z[i] = origin.z();
            packet.ray.dir_x[i] = dir.x();
            packet.ray.dir_y[i] = dir.y();
            packet.ray.dir_z[i] = dir.z();
            packet.ray.tnear[i] = 0.0f;
            packet.ray.tfar[i] = std::numeric_limits<float>::infinity();
            if (on && moving_only) packet.ray.tfar[i] = hits->depth[v * width + u];
            packet.ray.time[i] = 0.0f;
            packet.ray.mask[i] = 0xffffffffu;
            packet.ray.id[i] = i;
            packet.ray.flags[i] = 0;
            packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
            local_rays += on;
          }
          rtcIntersect16(valid, scene, &context, &packet);
          for (int i = 0; i < 16; ++i) {
            if (!valid[i]) continue;
            const int u = u0 + i % kTile;
            const int v = v0 + i / kTile;
            const size_t p = static_cast<size_t>(v) * width + u;
            if (packet.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
              if (!moving_only) {
                hits->depth[p] = std::numeric_limits<float>::infinity();
                hits->object[p] = kNoObject;
                hits->face[p] = 0;
                hits->cos_incidence[p] = 0.0f;
              }
              continue;
            }
            uint32_t object = kNoObject;
            if (instanced) object = instance_object[packet.hit.instID[0][i]];
            if (object == kNoObject) object = s.static_geometry_object[packet.hit.geomID[i]];
            Eigen::Vector3f normal(packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i]);
            normal = world_R_object[object] * normal;
            const Eigen::Vector3f dir(packet.ray.dir_x[i], packet.ray.dir_y[i],
                                      packet.ray.dir_z[i]);
            const float normal_norm = normal.norm();
            const float norms = normal_norm * dir.norm();
            const float dot = normal.dot(dir);
            // Face the camera: the sensor sees the side the ray hits.
            if (normal_norm > 0) normal *= (dot > 0 ? -1.0f : 1.0f) / normal_norm;
            hits->normal[3 * p] = normal.x();
            hits->normal[3 * p + 1] = normal.y();
            hits->normal[3 * p + 2] = normal.z();
            hits->depth[p] = packet.ray.tfar[i];
            hits->object[p] = object;
            hits->face[p] = packet.hit.primID[i];
            hits->cos_incidence[p] = norms > 0 ? std::min(1.0f, std::abs(dot) / norms) : 0.0f;
          }
        }
        cast.fetch_add(local_rays, std::memory_order_relaxed);
      });
  impl_->rays.fetch_add(cast.load());
  impl_->Check();
}

}  // namespace mmh::sim
