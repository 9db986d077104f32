// Ray casting for the sensor: the static table-top scene built once, moving objects (proxy, hand,
// slider block) as instances whose poses change per frame. Embree stays inside ray_scene.cc.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "sim/materials.h"

namespace mmh::sim {

// Object index of pixels whose ray hit nothing.
inline constexpr uint32_t kNoObject = 0xffffffffu;

// One row interval of pixels [first, last] to cast.
struct PixelSpan {
  int row = 0;
  int first = 0;
  int last = -1;
};

// Primary-ray hits of a set of pixels, #height by #width row-major; pixels outside the cast spans
// are left untouched.
struct HitBuffer {
  // Depth along the optical axis [m] (the ray parameter: rays have unit z in the camera frame);
  // +infinity where nothing was hit.
  std::vector<float> depth;
  // Object (index from AddObject, in adding order: static meshes and moving objects share one
  // numbering) and face hit; kNoObject where nothing was hit.
  std::vector<uint32_t> object;
  std::vector<uint32_t> face;
  // Cosine of the angle between the viewing ray and the surface normal, in [0, 1].
  std::vector<float> cos_incidence;
  // Unit world-frame surface normal, #pixels by 3, facing the camera.
  std::vector<float> normal;

  void Resize(int pixel_count);
};

// The hits of one 4x4 tile of pixels, structure of arrays (the renderer's write-back reads them
// lane by lane without gathering). Lane i is pixel (u0 + i % 4, v0 + i / 4).
struct HitPacket {
  static constexpr int kTile = 4;
  static constexpr int kLanes = kTile * kTile;
  int u0 = 0;
  int v0 = 0;
  // Bit i: lane i was cast (its pixel lies in the spans).
  uint32_t cast = 0;
  // Bit i: lane i hit something (Target::kMoving: something nearer than its max_depth); only
  // these lanes' fields below are set.
  uint32_t hit = 0;
  alignas(64) float depth[kLanes];  // along the optical axis [m]
  alignas(64) uint32_t object[kLanes];
  alignas(64) uint32_t face[kLanes];
  // Unit world-frame surface normal facing the camera.
  alignas(64) float normal_x[kLanes];
  alignas(64) float normal_y[kLanes];
  alignas(64) float normal_z[kLanes];
  // Cosine of the angle between the viewing ray and the surface normal, in [0, 1].
  alignas(64) float cos_incidence[kLanes];
};

// Receives the packets of a Cast; called concurrently from several threads, each packet once.
class HitSink {
 public:
  virtual ~HitSink() = default;
  virtual void Consume(const HitPacket& packet) = 0;
};

class RayScene {
 public:
  // Creates the Embree device. Embree errors are reported through its error callback and thrown
  // as std::runtime_error naming the Embree error code, never ignored.
  RayScene();
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // Adds a mesh (validated: ValidateMesh names `name`). Static meshes are placed once with
  // world_T_mesh; moving objects start at the identity and are placed by SetPose. Returns the
  // object index. All objects must be added before the first Commit.
  uint32_t AddStatic(const std::string& name, const TriangleMesh& mesh, const Rigid3& world_T_mesh);
  uint32_t AddMoving(const std::string& name, const TriangleMesh& mesh);

  // The object's material in the IR band (default SurfaceMaterial{}); read by the structured-light
  // sensor mode only.
  void SetMaterial(uint32_t object, const SurfaceMaterial& material);
  const SurfaceMaterial& material(uint32_t object) const;

  // Moves / hides a moving object; takes effect at the next Commit.
  void SetPose(uint32_t object, const Rigid3& world_T_object);
  void SetVisible(uint32_t object, bool visible);
  // Builds the static scene's BVH the first time, then only the instances' top level: cheap.
  void Commit();

  int object_count() const;
  const std::string& object_name(uint32_t object) const;
  const TriangleMesh& object_mesh(uint32_t object) const;
  bool is_moving(uint32_t object) const;
  // Pose of an object: static ones where they were placed, moving ones at their current pose.
  const Rigid3& world_T_object(uint32_t object) const;
  // World bounds of a moving object at its current pose (empty when hidden).
  Bounds3 WorldBounds(uint32_t object) const;

  // Casts the camera rays of the pixels in `spans` (pixel (u, v) looks along
  // ((u - cx) / fx, (v - cy) / fy, 1) in the camera frame) and writes their hits into `hits`.
  // kStatic: the static scene alone (the cache of the incremental renderer); kMoving: only the
  // moving objects, and only hits nearer than the depth already in `hits` (the cached static hit)
  // replace it; kAll: everything. Spans are cast in 4x4 packets; the result of a pixel does not
  // depend on the spans or on the thread that casts it.
  enum class Target { kAll, kStatic, kMoving };
  void Cast(const PinholeIntrinsics& intrinsics, const Rigid3& world_T_camera,
            std::span<const PixelSpan> spans, Target target, HitBuffer* hits) const;

  // The same rays handed to `sink` packet by packet (the caller keeps only what it needs). For
  // kMoving, max_depth (#height by #width, row-major) bounds each ray: only nearer hits count;
  // it may be null for kAll and kStatic (unbounded rays).
  void Cast(const PinholeIntrinsics& intrinsics, const Rigid3& world_T_camera,
            std::span<const PixelSpan> spans, Target target, const float* max_depth,
            HitSink* sink) const;

  // The rays of `spans` against one moving object alone (its own BVH, the rays moved into its
  // frame: no top-level traversal), bounded by max_depth (#height by #width, row-major): only
  // nearer hits reach the sink. Cheaper than kMoving when the caller knows which pixels each
  // object can cover; casting the objects one after another over a depth buffer that the sink
  // updates gives the nearest hit of all of them. Nothing happens for a hidden object.
  void CastObject(uint32_t object, const PinholeIntrinsics& intrinsics,
                  const Rigid3& world_T_camera, std::span<const PixelSpan> spans,
                  const float* max_depth, HitSink* sink) const;

  // Number of rays cast so far (for benchmarks).
  uint64_t rays_cast() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Spans covering the whole image.
std::vector<PixelSpan> FullImageSpans(const PinholeIntrinsics& intrinsics);

}  // namespace mmh::sim
