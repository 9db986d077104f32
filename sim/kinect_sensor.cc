#include "sim/kinect_sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <numbers>
#include <numeric>
#include <span>

#include "core/error.h"
#include "sim/depth_registration.h"
#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "sim/internal/color_noise.h"
#include "sim/internal/counter_random.h"
#include "sim/internal/depth_kernels.h"
#include "sim/internal/occlusion_scan.h"
#include "sim/internal/screen_cover.h"
#include "sim/internal/speckle_matcher.h"

namespace mmh::sim {
namespace {

using internal::ClusterBounds;
using internal::ColorAliasTable;
using internal::ColorParams;
using internal::ColorRow;
using internal::ConvexHull;
using internal::CosStep;
using internal::CounterHash;
using internal::CoverConvexPolygon;
using internal::DepthParams;
using internal::DepthRow;
using internal::DepthSample;
using internal::DisparityLanes;
using internal::kCosSteps;
using internal::MergeRowIntervals;
using internal::Mix64;
using internal::OcclusionCacheRow;
using internal::OcclusionWindow;
using internal::SourceColumns;
using internal::UseAvx512;
using internal::UseAvx512Default;
#if MMH_SENSOR_AVX512
using internal::OcclusionScanAvx512;
#endif

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double SrgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
double LinearToSrgb(double c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}
constexpr int kEncodeSteps = 4096;

}  // namespace

struct KinectSensor::Impl {
  // Per-pixel geometry of one view, #pixels (colour #pixels by 3), row-major.
  struct Geometry {
    std::vector<float> depth;          // along the optical axis [m]; +inf where nothing was hit
    std::vector<float> disparity;      // IR disparity f b / z [px]; 0 where nothing was hit
    std::vector<float> cos_incidence;  // in [0, 1]; 0 where nothing was hit
    std::vector<uint8_t> color;        // shaded sRGB before noise (views that deliver colour)
    std::vector<uint8_t> occluded;     // hidden from occluder sources: their bits, 0 = seen
    // The hit's SurfaceMaterial (structured-light mode only): ir_albedo (1 - specularity) and
    // specularity; 0 where nothing was hit.
    std::vector<float> ir_diffuse, ir_specular;
    // SurfaceMaterial::subsurface_mm in metres (only where a material in the scene has one).
    std::vector<float> ir_subsurface;

    void Resize(int pixels, bool color_too, bool ir_too, bool subsurface_too) {
      depth.assign(pixels, std::numeric_limits<float>::infinity());
      disparity.assign(pixels, 0.0f);
      cos_incidence.assign(pixels, 0.0f);
      color.assign(color_too ? 3 * static_cast<size_t>(pixels) : 0, 0);
      occluded.assign(pixels, 0);
      ir_diffuse.assign(ir_too ? pixels : 0, 0.0f);
      ir_specular.assign(ir_too ? pixels : 0, 0.0f);
      ir_subsurface.assign(ir_too && subsurface_too ? pixels : 0, 0.0f);
    }
  };

  // One camera's cached (static scene) and working geometry.
  struct View {
    PinholeIntrinsics intrinsics;
    Rigid3 world_T_view;
    bool needs_color = false;
    bool needs_occlusion = false;
    bool needs_ir = false;  // materials per pixel (the structured-light mode's depth view)
    // x positions of the light sources whose occlusion makes pixels missing, in this view's frame,
    // and the bit each sets in Geometry::occluded (internal::kProjectorShadowBit, kIrCameraBit).
    std::vector<double> occluder_sources;
    std::vector<uint8_t> occluder_bits;
    Geometry cache, current;
    bool cached = false;
    bool all_dirty = false;  // the working buffers differ from the cache anywhere
    std::vector<PixelSpan> dirty;
    // Per occluder source, the static scene's scan (OcclusionCacheRow): inclusive extrema and
    // flags, #height by padded width (a multiple of 16).
    std::vector<std::vector<float>> source_extremum;
    std::vector<std::vector<uint8_t>> source_flags;
    // Per row, the columns [first, last] whose occlusion flags the last frame wrote (first > last:
    // none); they get the cached flags back before the row's next windowed scan.
    std::vector<PixelSpan> occlusion_written;
  };

  // The cast's write-back: keeps only what the model needs (depth, disparity, incidence cosine)
  // and the shaded colour of the hit, so that no per-pixel normal or face is stored.
  class GeometrySink final : public HitSink {
   public:
    GeometrySink(const Impl& sensor, View& view, bool hits_only)
        : s_(sensor),
          width_(view.intrinsics.width),
          hits_only_(hits_only),
          depth_(view.current.depth.data()),
          disparity_(view.current.disparity.data()),
          cos_incidence_(view.current.cos_incidence.data()),
          color_(view.needs_color ? view.current.color.data() : nullptr),
          ir_diffuse_(view.needs_ir ? view.current.ir_diffuse.data() : nullptr),
          ir_specular_(view.needs_ir ? view.current.ir_specular.data() : nullptr),
          ir_subsurface_(view.current.ir_subsurface.empty() ? nullptr
                                                            : view.current.ir_subsurface.data()) {}

    void Consume(const HitPacket& packet) override {
      float* __restrict depth = depth_;
      float* __restrict disparity = disparity_;
      float* __restrict cos_incidence = cos_incidence_;
      uint8_t* __restrict color = color_;
      const float disparity_scale = s_.disparity_scale;
      alignas(64) float lane_disparity[HitPacket::kLanes];
      DisparityLanes(packet.depth, disparity_scale, lane_disparity);
      const uint32_t write = hits_only_ ? packet.hit : packet.cast;
      for (int r = 0; r < HitPacket::kTile; ++r) {
        const int shift = r * HitPacket::kTile;
        const uint32_t row_write = (write >> shift) & 0xfu;
        if (row_write == 0) continue;
        const size_t base = static_cast<size_t>(packet.v0 + r) * width_ + packet.u0;
        if (row_write == 0xfu && ((packet.hit >> shift) & 0xfu) == 0xfu) {
          // Four hits side by side (the common case).
          std::memcpy(depth + base, packet.depth + shift, sizeof(float) * HitPacket::kTile);
          std::memcpy(disparity + base, lane_disparity + shift, sizeof(float) * HitPacket::kTile);
          std::memcpy(cos_incidence + base, packet.cos_incidence + shift,
                      sizeof(float) * HitPacket::kTile);
          if (color != nullptr) {
            for (int c = 0; c < HitPacket::kTile; ++c) {
              s_.Shade(packet, shift + c, color + 3 * (base + c));
            }
          }
          if (ir_diffuse_ != nullptr) {
            for (int c = 0; c < HitPacket::kTile; ++c) WriteMaterial(packet, shift + c, base + c);
          }
          continue;
        }
        for (int c = 0; c < HitPacket::kTile; ++c) {
          if (!((row_write >> c) & 1u)) continue;
          const int i = shift + c;
          const size_t p = base + c;
          if (!((packet.hit >> i) & 1u)) {
            depth[p] = std::numeric_limits<float>::infinity();
            disparity[p] = 0.0f;
            cos_incidence[p] = 0.0f;
            if (color != nullptr) std::fill_n(color + 3 * p, 3, s_.background);
            if (ir_diffuse_ != nullptr) ir_diffuse_[p] = ir_specular_[p] = 0.0f;
            if (ir_subsurface_ != nullptr) ir_subsurface_[p] = 0.0f;
            continue;
          }
          depth[p] = packet.depth[i];
          disparity[p] = lane_disparity[i];
          cos_incidence[p] = packet.cos_incidence[i];
          if (color != nullptr) s_.Shade(packet, i, color + 3 * p);
          if (ir_diffuse_ != nullptr) WriteMaterial(packet, i, p);
        }
      }
    }

   private:
    void WriteMaterial(const HitPacket& packet, int i, size_t p) {
      const uint32_t object = packet.object[i];
      const std::vector<float>& faces = s_.face_ir_diffuse[object];
      ir_diffuse_[p] = faces.empty() ? s_.object_ir_diffuse[object] : faces[packet.face[i]];
      ir_specular_[p] = s_.object_ir_specular[object];
      if (ir_subsurface_ != nullptr) ir_subsurface_[p] = s_.object_subsurface_m[object];
    }

    const Impl& s_;
    int width_;
    bool hits_only_;
    float* depth_;
    float* disparity_;
    float* cos_incidence_;
    uint8_t* color_;
    float* ir_diffuse_;
    float* ir_specular_;
    float* ir_subsurface_;
  };

  // Lambertian shading in linear light of a unit normal facing the camera, then sRGB.
  void ShadeNormal(const uint8_t* albedo, float nx, float ny, float nz, uint8_t* out) const {
    const float n_dot_l = nx * light[0] + ny * light[1] + nz * light[2];
    const float light_factor = ambient + diffuse * std::max(0.0f, n_dot_l);
    for (int c = 0; c < 3; ++c) {
      const float linear = std::min(1.0f, srgb_to_linear[albedo[c]] * light_factor);
      out[c] = linear_to_srgb[static_cast<int>(linear * kEncodeSteps + 0.5f)];
    }
  }
  // Colour of lane i of a packet: static faces from the table made at construction (flat
  // shading: a static face's normal and the side the camera sees are fixed), moving ones shaded.
  void Shade(const HitPacket& packet, int i, uint8_t* out) const {
    const uint32_t object = packet.object[i];
    const uint8_t* shaded = static_face_color[object];
    if (shaded != nullptr) {
      std::memcpy(out, shaded + 3 * static_cast<size_t>(packet.face[i]), 3);
      return;
    }
    ShadeNormal(face_colors[object] + 3 * static_cast<size_t>(packet.face[i]), packet.normal_x[i],
                packet.normal_y[i], packet.normal_z[i], out);
  }

  // Per static object, the shaded sRGB colour of every face as the colour camera sees it
  // (#faces by 3); null for moving objects.
  void ShadeStaticFaces() {
    const Eigen::Vector3d eye = color_view.world_T_view.translation;
    static_face_storage.resize(scene->object_count());
    static_face_color.assign(scene->object_count(), nullptr);
    for (int o = 0; o < scene->object_count(); ++o) {
      if (moving[o]) continue;
      const TriangleMesh& mesh = scene->object_mesh(o);
      const Rigid3& world_T_mesh = scene->world_T_object(o);
      std::vector<uint8_t>& shaded = static_face_storage[o];
      shaded.resize(3 * static_cast<size_t>(mesh.face_count()));
      for (int f = 0; f < mesh.face_count(); ++f) {
        Eigen::Vector3d corner[3];
        for (int k = 0; k < 3; ++k) {
          corner[k] = world_T_mesh * mesh.vertices.row(mesh.faces(f, k)).transpose().cast<double>();
        }
        Eigen::Vector3d n = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
        const double norm = n.norm();
        n = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero();
        if (n.dot(corner[0] - eye) > 0) n = -n;  // the side the camera sees
        ShadeNormal(face_colors[o] + 3 * static_cast<size_t>(f), static_cast<float>(n.x()),
                    static_cast<float>(n.y()), static_cast<float>(n.z()), &shaded[3 * f]);
      }
      static_face_color[o] = shaded.data();
    }
  }

  KinectSensorOptions options;
  const RayScene* scene = nullptr;
  Rigid3 world_T_camera;
  View color_view, ir_view;
  SensorTimings timings;
  std::vector<const uint8_t*> face_colors;  // per object
  std::vector<float> object_ir_diffuse, object_ir_specular;  // per object (SurfaceMaterial)
  std::vector<float> object_subsurface_m;                    // per object, metres
  bool any_subsurface = false;                               // some object's is above 0
  // Per object, per face: the diffuse IR reflectance of a printed surface (colour_contrast > 0);
  // empty: object_ir_diffuse for every face.
  std::vector<std::vector<float>> face_ir_diffuse;
  std::unique_ptr<internal::SpeckleMatcher> speckle;  // structured-light mode
  std::vector<uint16_t> ir_image;                      // structured-light mode, depth view
  std::vector<MissingCause> last_causes;     // when requested (KeepMissingCauses)
  // Registered structured light matched on the IR camera's grid: the IR grid's depth and causes,
  // then carried to the colour camera's (RegisterDepth).
  bool ir_grid = false;
  std::vector<uint16_t> ir_grid_depth;
  std::vector<float> ir_grid_depth_m;  // the same in metres, for RegisterDepth
  std::vector<MissingCause> ir_grid_causes;
  std::vector<std::vector<uint8_t>> static_face_storage;
  std::vector<const uint8_t*> static_face_color;  // per object (ShadeStaticFaces)
  std::vector<bool> moving;
  std::vector<std::vector<Bounds3>> moving_clusters;  // per object (ClusterBounds), object frame
  // Shading.
  float light[3] = {0, 0, 1};
  float ambient = 0, diffuse = 0;
  uint8_t background = 0;
  float disparity_scale = 0;  // f b [px m] of the IR camera
  // Lookup tables.
  std::array<float, 256> srgb_to_linear{};
  std::vector<uint8_t> linear_to_srgb;  // kEncodeSteps + 1
  std::vector<float> lateral_cross;     // per cos step: P(offset rounds across the edge)
  std::vector<float> drop;              // per cos step: P(grazing or speckle dropout)
  std::vector<float> grazing_sigma;     // per cos step, times 1/sqrt(z) at use
  int flat_step = kCosSteps;            // DepthParams::flat_step
  std::vector<uint32_t> color_alias;    // ColorAliasTable
  int color_slot_bits = 1;

  // The view whose depth the frame delivers, and the one the structured light is matched in: the
  // IR camera's own unless the depth is registered and matched on the delivered grid (the
  // model's shortcut; StructuredLightOptions::match_on_ir_grid false).
  View& depth_view() { return options.registered ? color_view : ir_view; }
  View& match_view() { return options.registered && !ir_grid ? color_view : ir_view; }
  Rigid3 ColorTDepth() { return color_view.world_T_view.Inverse() * depth_view().world_T_view; }

  // One row of the depth image: the vector part for every pixel, then, for edge pixels only,
  // the edge dropout and the lateral noise (an edge pixel takes the depth and incidence of its
  // neighbour across the largest jump).
  // edge: #w scratch; edge_bits: #ceil(w / 64) scratch.
  template <bool kQuantise>
  static void NoisyDepthRow(const DepthParams& q, const Geometry& g, int v, int w, int h,
                            uint8_t* edge, uint64_t* edge_bits, uint32_t* hash, float* normal,
                            uint16_t* out) {
    const size_t row = static_cast<size_t>(v) * w;
    const float* d = &g.disparity[row];
    const float* up = v > 0 ? d - w : d;
    const float* down = v + 1 < h ? d + w : d;
    DepthRow<kQuantise>(q, up, d, down, &g.depth[row], &g.cos_incidence[row], &g.occluded[row],
                        static_cast<uint32_t>(row), w, edge, edge_bits, hash, normal, out);
    const float uniform = 1.0f / 65536.0f;
    // Edges are rare: only their bits are visited, in order.
    for (int word = 0; word < (w + 63) / 64; ++word) {
      for (uint64_t bits = edge_bits[word]; bits != 0; bits &= bits - 1) {
        EdgePixel<kQuantise>(q, g, v, w, h, word * 64 + std::countr_zero(bits), uniform, hash,
                             normal, out);
      }
    }
  }

  // The edge dropout and lateral noise of edge pixel u of row v (NoisyDepthRow).
  template <bool kQuantise>
  static void EdgePixel(const DepthParams& q, const Geometry& g, int v, int w, int h, int u,
                        float uniform, const uint32_t* hash, const float* normal, uint16_t* out) {
    const size_t row = static_cast<size_t>(v) * w;
    const float* d = &g.disparity[row];
    const uint32_t hash_a = CounterHash(q.key_a, static_cast<uint32_t>(row + u));
    const float u_lateral = static_cast<float>(hash_a & 0xffffu) * uniform;
    const float u_edge = static_cast<float>((hash_a >> 16) & 0xffffu) * uniform;
    if (u_edge < q.edge_probability) {
      out[u] = 0;
      return;
    }
    const size_t p = row + u;
    // The neighbour across the largest jump.
    size_t across = p;
    float largest = -1.0f;
    auto consider = [&](bool inside, size_t n) {
      if (!inside) return;
      const float j = std::abs(g.disparity[n] - d[u]);
      if (j > largest) {
        largest = j;
        across = n;
      }
    };
    consider(u > 0, p - 1);
    consider(u + 1 < w, p + 1);
    consider(v > 0, p - w);
    consider(v + 1 < h, p + w);
    // Lateral noise: the edge moves by the rounded N(0, sigma_L) offset; towards the neighbour
    // across the edge in half of the cases where it rounds to one pixel or more.
    if (u_lateral < q.lateral_cross[CosStep(g.cos_incidence[p])] &&
        std::isfinite(g.depth[across])) {
      out[u] = DepthSample<kQuantise>(q, g.depth[across], g.cos_incidence[across], true, hash[u],
                                      normal[u]);
    }
  }

  // The exact model without noise (for geometry tests).
  static void ExactDepthRow(const DepthParams& q, const Geometry& g, int v, int w, uint16_t* out) {
    const size_t row = static_cast<size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      float z = g.depth[row + u];
      bool keep = std::isfinite(z) && !g.occluded[row + u] &&
                  g.cos_incidence[row + u] >= q.grazing_cos_limit;
      if (keep && q.quantise) {
        const float raw = std::floor(q.raw_offset - q.lattice / z + 0.5f);
        keep = raw >= 0.0f && raw <= 2046.0f;
        if (keep) z = q.lattice / (q.raw_offset - raw);
      }
      keep = keep && z >= q.min_depth && z <= q.max_depth;
      out[u] =
          keep ? static_cast<uint16_t>(std::min(65535.0f, std::floor(z * q.inverse_scale + 0.5f)))
               : 0;
    }
  }

  // Marks the pixels of `rows` hidden from any occluder source: a row scan per source (see the
  // header). The scan runs over u_s = u - f_x s / z = u - (f_x s / f b) disparity.
  void Occlude(View& view, std::span<const int> rows) {
    if (!view.needs_occlusion) return;
    const int width = view.intrinsics.width;
    Geometry& g = view.current;
    const double fx = view.intrinsics.fx;
    view.occlusion_written.resize(view.intrinsics.height);
    for (int v : rows) view.occlusion_written[v] = {v, 0, width - 1};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                        std::vector<float> us(width + 16);
                        std::vector<uint8_t> scan(2 * (width + 16));
                        for (size_t k = r.begin(); k != r.end(); ++k) {
                          const size_t row = static_cast<size_t>(rows[k]) * width;
                          OccludeRow(&g.disparity[row], width, fx, view.occluder_sources,
                                     view.occluder_bits, us.data(), scan.data(), &g.occluded[row]);
                        }
                      });
  }

  // The scan values of one row for source_x (see Occlude), padded with the source's `none` to a
  // multiple of 16 (us: scratch of at least width + 16 entries); returns the padded width.
  int SourceRow(const float* disparity, int width, double fx, double source_x, float* us) const {
    const int padded = (width + 15) / 16 * 16;
    const auto shift = static_cast<float>(fx * source_x / disparity_scale);
    // Pixels that see nothing never bound the scan.
    const float none = (source_x > 0 ? 1.0f : -1.0f) * std::numeric_limits<float>::infinity();
    SourceColumns(disparity, width, shift, none, us);
    std::fill(us + width, us + padded, none);
    return padded;
  }

  // The static scene's scans per source (view.cache must hold it), for OccludeWindows.
  void CacheOcclusion(View& view) const {
    if (!view.needs_occlusion) return;
    const int width = view.intrinsics.width;
    const int height = view.intrinsics.height;
    const int padded = (width + 15) / 16 * 16;
    const size_t sources = view.occluder_sources.size();
    view.source_extremum.assign(sources, std::vector<float>(static_cast<size_t>(padded) * height));
    view.source_flags.assign(sources, std::vector<uint8_t>(static_cast<size_t>(padded) * height));
    std::vector<float> us(width + 16);
    for (size_t k = 0; k < sources; ++k) {
      const double source_x = view.occluder_sources[k];
      for (int v = 0; v < height; ++v) {
        SourceRow(&view.cache.disparity[static_cast<size_t>(v) * width], width, view.intrinsics.fx,
                  source_x, us.data());
        const size_t at = static_cast<size_t>(v) * padded;
        OcclusionCacheRow(us.data(), padded, source_x > 0, &view.source_extremum[k][at],
                          &view.source_flags[k][at]);
      }
    }
  }

  // Occlusion of an incremental frame: per row whose geometry differs from the static scene in
  // columns [first, last] (this frame's or the last frame's moving objects), the cached flags
  // back where the last frame wrote, then per source the scan over the window that the change
  // can affect (OcclusionWindowPortable), cached flags elsewhere. Gives the flags of Occlude.
  void OccludeWindows(View& view, std::span<const PixelSpan> changes) {
    if (!view.needs_occlusion) return;
    const int width = view.intrinsics.width;
    const int padded = (width + 15) / 16 * 16;
    Geometry& g = view.current;
    const double fx = view.intrinsics.fx;
    const size_t sources = view.occluder_sources.size();
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, changes.size(), 16),
        [&](const tbb::blocked_range<size_t>& r) {
          std::vector<float> us(width + 16);
          std::vector<std::vector<uint8_t>> flags(sources, std::vector<uint8_t>(padded));
          std::vector<PixelSpan> windows(sources);
          for (size_t c = r.begin(); c != r.end(); ++c) {
            const PixelSpan& change = changes[c];
            const size_t row = static_cast<size_t>(change.row) * width;
            const size_t cached_row = static_cast<size_t>(change.row) * padded;
            PixelSpan& written = view.occlusion_written[change.row];
            if (written.first <= written.last) {
              std::copy(&view.cache.occluded[row + written.first],
                        &view.cache.occluded[row + written.last] + 1,
                        &g.occluded[row + written.first]);
            }
            int lo = change.first, hi = change.last;
            for (size_t k = 0; k < sources; ++k) {
              const double source_x = view.occluder_sources[k];
              SourceRow(&g.disparity[row], width, fx, source_x, us.data());
              const float* cached = &view.source_extremum[k][cached_row];
              PixelSpan& w = windows[k];
              const bool from_right = source_x > 0;
              const int far_end =
                  (from_right ? OcclusionWindow<true>
                              : OcclusionWindow<false>)(us.data(), cached, padded, change.first,
                                                        change.last, flags[k].data());
              // The near end: the start of the block holding the change's last (first) column.
              w.first = from_right ? far_end : change.first / 16 * 16;
              w.last = from_right ? change.last / 16 * 16 + 15 : far_end;
              lo = std::min(lo, w.first);
              hi = std::max(hi, w.last);
            }
            hi = std::min(hi, width - 1);
            for (size_t k = 0; k < sources; ++k) {
              const uint8_t* cached_flags = &view.source_flags[k][cached_row];
              for (int u = lo; u < windows[k].first; ++u) flags[k][u] = cached_flags[u];
              for (int u = windows[k].last + 1; u <= hi; ++u) flags[k][u] = cached_flags[u];
            }
            const float* d = &g.disparity[row];
            uint8_t* occluded = &g.occluded[row];
            for (int u = lo; u <= hi; ++u) {
              uint8_t any = 0;
              for (size_t k = 0; k < sources; ++k) {
                any |= static_cast<uint8_t>(flags[k][u] * view.occluder_bits[k]);
              }
              occluded[u] = d[u] != 0.0f ? any : uint8_t{0};
            }
            written = {change.row, lo, hi};
          }
        });
  }

  // One source's occlusion scan of a row (us from SourceRow, padded): scan[u] = 1 where the
  // source does not see pixel u.
  static void ScanSource(const float* us, int width, int padded, bool from_right, bool vector,
                         uint8_t* scan) {
    static_cast<void>(vector);  // without the AVX-512 kernels
#if MMH_SENSOR_AVX512
    if (vector) {
      if (from_right) {
        OcclusionScanAvx512<true>(us, padded, scan);
      } else {
        OcclusionScanAvx512<false>(us, padded, scan);
      }
      return;
    }
#endif
    if (from_right) {
      // Scanning from the source's side (+x): hidden iff not left of everything right of it.
      float lowest = std::numeric_limits<float>::infinity();
      for (int u = width - 1; u >= 0; --u) {
        scan[u] |= static_cast<uint8_t>(us[u] >= lowest);
        lowest = std::min(lowest, us[u]);
      }
    } else {
      float highest = -std::numeric_limits<float>::infinity();
      for (int u = 0; u < width; ++u) {
        scan[u] |= static_cast<uint8_t>(us[u] <= highest);
        highest = std::max(highest, us[u]);
      }
    }
  }

  // us: scratch of at least width + 16 entries; scan: of twice that (one source's flags, and
  // the sources' bits).
  void OccludeRow(const float* disparity, int width, double fx, const std::vector<double>& sources,
                  const std::vector<uint8_t>& bits, float* us, uint8_t* scan,
                  uint8_t* occluded) const {
    const int padded = (width + 15) / 16 * 16;
    const bool vector = UseAvx512().load(std::memory_order_relaxed) && MMH_SENSOR_AVX512;
    uint8_t* all = scan + padded;
    std::fill(all, all + padded, 0);
    for (size_t k = 0; k < sources.size(); ++k) {
      std::fill(scan, scan + padded, 0);
      SourceRow(disparity, width, fx, sources[k], us);
      ScanSource(us, width, padded, sources[k] > 0, vector, scan);
      for (int u = 0; u < padded; ++u) all[u] |= static_cast<uint8_t>(scan[u] * bits[k]);
    }
    // Pixels that see nothing are not occluded (they are missing anyway).
    for (int u = 0; u < width; ++u) occluded[u] = disparity[u] != 0.0f ? all[u] : uint8_t{0};
  }

  // The pixels whose rays can hit a moving object: per object, the projections of its cluster
  // boxes at its current pose, scan-converted with a pixel of margin (a ray through a pixel hits
  // a box only if the pixel centre lies in the box's projected hull). An object reaching behind
  // the camera covers the whole image.
  struct ObjectSpans {
    uint32_t object;
    std::vector<PixelSpan> spans;
  };
  // Per visible moving object its spans; `all` gets their union.
  std::vector<ObjectSpans> MovingSpans(const View& view, std::vector<PixelSpan>* all) const {
    const Rigid3 view_T_world = view.world_T_view.Inverse();
    const PinholeIntrinsics& k = view.intrinsics;
    std::vector<ObjectSpans> result;
    std::vector<PixelSpan> union_rows;
    std::vector<Eigen::Vector2d> corners(8);
    std::vector<PixelSpan> rows;
    for (int o = 0; o < scene->object_count(); ++o) {
      if (!moving[o] || scene->WorldBounds(o).empty()) continue;
      const Rigid3 view_T_object = view_T_world * scene->world_T_object(o);
      rows.clear();
      bool behind = false;
      for (const Bounds3& box : moving_clusters[o]) {
        for (int corner = 0; corner < 8 && !behind; ++corner) {
          const Eigen::Vector3d p((corner & 1) ? box.max.x() : box.min.x(),
                                  (corner & 2) ? box.max.y() : box.min.y(),
                                  (corner & 4) ? box.max.z() : box.min.z());
          const Eigen::Vector3d c = view_T_object * p;
          behind = c.z() < 1e-3;
          corners[corner] = k.Project(c);
        }
        if (behind) break;
        CoverConvexPolygon(ConvexHull(corners), k.width, k.height, &rows);
      }
      ObjectSpans object{static_cast<uint32_t>(o), {}};
      object.spans = behind ? FullImageSpans(k) : MergeRowIntervals(rows);
      union_rows.insert(union_rows.end(), object.spans.begin(), object.spans.end());
      if (!object.spans.empty()) result.push_back(std::move(object));
    }
    *all = MergeRowIntervals(union_rows);
    return result;
  }

  // Copies the cached static geometry of `spans` into the working buffers.
  static void RestoreSpans(std::span<const PixelSpan> spans, View& view) {
    const int width = view.intrinsics.width;
    const Geometry& from = view.cache;
    Geometry& to = view.current;
    for (const PixelSpan& s : spans) {
      const size_t a = static_cast<size_t>(s.row) * width + s.first;
      const size_t n = s.last - s.first + 1;
      std::copy_n(&from.depth[a], n, &to.depth[a]);
      std::copy_n(&from.disparity[a], n, &to.disparity[a]);
      std::copy_n(&from.cos_incidence[a], n, &to.cos_incidence[a]);
      if (view.needs_color) std::copy_n(&from.color[3 * a], 3 * n, &to.color[3 * a]);
      if (view.needs_ir) {
        std::copy_n(&from.ir_diffuse[a], n, &to.ir_diffuse[a]);
        std::copy_n(&from.ir_specular[a], n, &to.ir_specular[a]);
        if (!from.ir_subsurface.empty()) {
          std::copy_n(&from.ir_subsurface[a], n, &to.ir_subsurface[a]);
        }
      }
    }
  }

  // The working geometry of this frame: the static scene (cast, or restored from the cache where
  // the previous frame changed it), the moving objects cast over it within their screen bounds
  // (nearer hits replace the static ones), occlusion re-scanned where rows changed. Full and
  // incremental mode run the same casts on the same rays, so they give the same bytes.
  void UpdateGeometry(View& view, RenderMode mode) {
    const PinholeIntrinsics& k = view.intrinsics;
    const int pixels = k.pixel_count();
    std::vector<int> all_rows(k.height);
    std::iota(all_rows.begin(), all_rows.end(), 0);
    if (view.current.depth.size() != static_cast<size_t>(pixels)) {
      view.current.Resize(pixels, view.needs_color, view.needs_ir, any_subsurface);
    }
    auto t0 = Clock::now();
    bool all_rows_dirty = view.all_dirty;
    if (!view.cached || mode == RenderMode::kFull) {
      // The static scene, every pixel.
      const auto full = FullImageSpans(k);
      GeometrySink sink(*this, view, false);
      scene->Cast(k, view.world_T_view, full, RayScene::Target::kStatic, nullptr, &sink);
      const auto t1 = Clock::now();
      timings.cast += Seconds(t0, t1);
      if (!view.cached) {
        Occlude(view, all_rows);
        view.cache = view.current;
        CacheOcclusion(view);
        view.cached = true;
        view.dirty.clear();
        all_rows_dirty = false;
      } else {
        all_rows_dirty = true;
      }
      t0 = Clock::now();
      timings.occlusion += Seconds(t1, t0);
    } else {
      // Back to the cache where the previous frame differed from it.
      if (view.all_dirty) {
        RestoreSpans(FullImageSpans(k), view);
      } else {
        RestoreSpans(view.dirty, view);
      }
      const auto t1 = Clock::now();
      timings.restore += Seconds(t0, t1);
      t0 = t1;
    }
    std::vector<PixelSpan> spans;
    const std::vector<ObjectSpans> objects = MovingSpans(view, &spans);
    // One object after the other, each bounded by the depth so far: the nearest hit wins.
    GeometrySink sink(*this, view, true);
    for (const ObjectSpans& o : objects) {
      scene->CastObject(o.object, k, view.world_T_view, o.spans, view.current.depth.data(), &sink);
    }
    auto t1 = Clock::now();
    timings.cast += Seconds(t0, t1);
    // Rows whose occlusion can differ from the cache: those touched now or last frame (others
    // keep the cached occlusion: their depth equals the cache), each within the columns touched.
    if (all_rows_dirty) {
      Occlude(view, all_rows);
    } else {
      std::vector<PixelSpan> changes(k.height, PixelSpan{0, k.width, -1});
      for (const std::vector<PixelSpan>* list : {&view.dirty, &spans}) {
        for (const PixelSpan& s : *list) {
          PixelSpan& c = changes[s.row];
          c.row = s.row;
          c.first = std::min(c.first, s.first);
          c.last = std::max(c.last, s.last);
        }
      }
      std::erase_if(changes, [](const PixelSpan& c) { return c.first > c.last; });
      OccludeWindows(view, changes);
    }
    timings.occlusion += Seconds(t1, Clock::now());
    uint64_t recast = mode == RenderMode::kFull ? static_cast<uint64_t>(pixels) : 0;
    for (const PixelSpan& s : spans) recast += s.last - s.first + 1;
    timings.pixels_recast += recast;
    view.all_dirty = mode == RenderMode::kFull;
    view.dirty = spans;
  }

  // The structured-light mode's depth image: the IR image of the speckle pattern, then block
  // matching (internal::SpeckleMatcher).
  void StructuredLightDepth(uint64_t frame_key, uint16_t* depth, MissingCause* causes) {
    const View& dv = match_view();
    const Geometry& g = dv.current;
    internal::SpeckleScene scene{g.depth.data(),    g.disparity.data(),  g.cos_incidence.data(),
                                 g.occluded.data(), g.ir_diffuse.data(), g.ir_specular.data()};
    if (!g.ir_subsurface.empty()) {
      scene.subsurface_m = g.ir_subsurface.data();
      scene.focal_px = static_cast<float>(dv.intrinsics.fx);
    }
    ir_image.resize(g.depth.size());
    speckle->RenderIr(scene, static_cast<uint32_t>(Mix64(frame_key ^ 0x5851F42D4C957F2DULL)),
                      ir_image.data());
    internal::SpeckleOutput out;
    out.lattice = static_cast<float>(options.calibration.lattice_constant());
    out.raw_offset = static_cast<float>(options.calibration.raw_offset);
    out.subpixel_steps = static_cast<float>(options.calibration.subpixel_steps);
    out.quantise = options.quantise;
    out.min_depth = static_cast<float>(options.min_depth);
    out.max_depth = static_cast<float>(options.max_depth);
    out.inverse_scale = static_cast<float>(1.0 / kTumDepthScale);
    speckle->Match(scene, ir_image.data(), out, depth, causes);
  }

  // Structured light matched on the IR camera's grid and registered to the colour camera's, as
  // the device's driver does (sim/depth_registration.h, the exact footprint). A delivered pixel's
  // cause is its IR pixel's, that of the IR pixel whose true surface is nearest there when its
  // depth is missing; no IR pixel there: the IR camera did not see what the colour camera sees
  // (kShadow), or nothing was hit.
  void RegisteredStructuredLightDepth(uint64_t frame_key, uint16_t* depth) {
    const View& iv = ir_view;
    const size_t ir_pixels = iv.intrinsics.pixel_count();
    ir_grid_depth.resize(ir_pixels);
    const bool causes = !last_causes.empty();
    if (causes) ir_grid_causes.assign(ir_pixels, MissingCause::kValid);
    StructuredLightDepth(frame_key, ir_grid_depth.data(), causes ? ir_grid_causes.data() : nullptr);
    ir_grid_depth_m.resize(ir_pixels);
    for (size_t p = 0; p < ir_pixels; ++p) {
      ir_grid_depth_m[p] = static_cast<float>(ir_grid_depth[p] * kTumDepthScale);
    }
    const Rigid3 color_T_ir = color_view.world_T_view.Inverse() * iv.world_T_view;
    DepthRegistrationOptions registration;
    registration.footprint_growth_px = options.structured_light.registration_growth_px;
    const std::vector<float> registered = RegisterDepth(
        ir_grid_depth_m, iv.intrinsics, color_view.intrinsics, color_T_ir, registration);
    for (size_t p = 0; p < registered.size(); ++p) {
      depth[p] = static_cast<uint16_t>(std::lround(registered[p] / kTumDepthScale));
    }
    if (!causes) return;
    std::vector<int32_t> surface;
    RegisterDepth(iv.current.depth, iv.intrinsics, color_view.intrinsics, color_T_ir, registration,
                  &surface);
    for (size_t p = 0; p < registered.size(); ++p) {
      if (depth[p] != 0) {
        last_causes[p] = MissingCause::kValid;
      } else if (surface[p] < 0) {
        last_causes[p] = std::isfinite(color_view.current.depth[p]) ? MissingCause::kShadow
                                                                    : MissingCause::kNothing;
      } else {
        const MissingCause c = ir_grid_causes[surface[p]];
        last_causes[p] = c != MissingCause::kValid ? c : MissingCause::kShadow;
      }
    }
  }

  void Output(int index, RgbdFrame* frame) {
    View& dv = depth_view();
    View& cv = color_view;
    const PinholeIntrinsics& dk = dv.intrinsics;
    const PinholeIntrinsics& ck = cv.intrinsics;
    frame->index = index;
    // Whole microseconds, so that the 6-decimal timestamps of TUM folders read back exactly.
    frame->timestamp = std::round(index * 1e6 / options.frame_rate) / 1e6;
    frame->depth_scale = kTumDepthScale;
    frame->depth_intrinsics = dk;
    frame->color_intrinsics = ck;
    frame->color_T_depth = ColorTDepth();
    frame->depth.resize(dk.pixel_count());
    frame->rgb.resize(3 * static_cast<size_t>(ck.pixel_count()));

    DepthParams q;
    const uint64_t frame_key =
        Mix64(options.seed ^ Mix64(static_cast<uint64_t>(index) + 0x632be59bd9b4e019ULL));
    q.key_a = static_cast<uint32_t>(frame_key);
    q.key_b = static_cast<uint32_t>(frame_key >> 32);
    const uint64_t more_keys = Mix64(frame_key ^ 0xD1B54A32D192ED03ULL);
    q.key_c = static_cast<uint32_t>(more_keys >> 32);
    ColorParams color_params;
    color_params.key = static_cast<uint32_t>(more_keys);
    color_params.slot_bits = color_slot_bits;
    color_params.table = color_alias.data();
    q.noise = options.noise;
    q.quantise = options.quantise;
    q.lattice = static_cast<float>(options.calibration.lattice_constant());
    q.raw_offset = static_cast<float>(options.calibration.raw_offset);
    q.edge_jump = static_cast<float>(options.missing.edge_jump_px);
    q.edge_probability = static_cast<float>(options.missing.edge_probability);
    q.min_depth = static_cast<float>(options.min_depth);
    q.max_depth = static_cast<float>(options.max_depth);
    q.inverse_scale = static_cast<float>(1.0 / kTumDepthScale);
    q.axial_a = static_cast<float>(options.axial.constant);
    q.axial_b = static_cast<float>(options.axial.quadratic);
    q.axial_z0 = static_cast<float>(options.axial.quadratic_origin);
    q.grazing_cos_limit =
        static_cast<float>(std::cos(options.missing.grazing_to_deg * std::numbers::pi / 180.0));
    q.lateral_cross = lateral_cross.data();
    q.drop = drop.data();
    q.grazing_sigma = grazing_sigma.data();
    q.flat_step = flat_step;
    const int dw = dk.width;
    const int dh = dk.height;
    const int cw = ck.width;
    const int ch = ck.height;

    const bool structured = options.mode == SensorMode::kStructuredLight;
    if (structured && ir_grid) {
      RegisteredStructuredLightDepth(frame_key, frame->depth.data());
    } else if (structured) {
      StructuredLightDepth(frame_key, frame->depth.data(),
                           last_causes.empty() ? nullptr : last_causes.data());
    }
    // Depth and colour rows in one loop (one task wakes both cores once per frame).
    const int rows = std::max(dh, ch);
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, 16), [&](const tbb::blocked_range<int>& r) {
      std::vector<uint8_t> edge(dw);
      std::vector<uint64_t> edge_bits((dw + 63) / 64);
      std::vector<uint32_t> hash(dw);
      std::vector<float> normal(dw);
      for (int v = r.begin(); v != r.end(); ++v) {
        if (v < dh && !structured) {
          uint16_t* out = &frame->depth[static_cast<size_t>(v) * dw];
          if (!q.noise) {
            ExactDepthRow(q, dv.current, v, dw, out);
          } else if (q.quantise) {
            NoisyDepthRow<true>(q, dv.current, v, dw, dh, edge.data(), edge_bits.data(),
                                hash.data(), normal.data(), out);
          } else {
            NoisyDepthRow<false>(q, dv.current, v, dw, dh, edge.data(), edge_bits.data(),
                                 hash.data(), normal.data(), out);
          }
        }
        if (v < ch) {
          const size_t row = 3 * static_cast<size_t>(v) * cw;
          if (!q.noise) {
            std::copy_n(&cv.current.color[row], 3 * cw, &frame->rgb[row]);
          } else {
            ColorRow(color_params, &cv.current.color[row],
                     static_cast<uint32_t>(v) * static_cast<uint32_t>(3 * cw), 3 * cw,
                     &frame->rgb[row]);
          }
        }
      }
    });
  }
};

KinectSensor::KinectSensor(const KinectSensorOptions& options, const RayScene* scene,
                           const Rigid3& world_T_camera, const std::string& options_name)
    : impl_(std::make_unique<Impl>()) {
  options.Validate(options_name);
  Impl& s = *impl_;
  s.options = options;
  s.scene = scene;
  s.world_T_camera = world_T_camera;
  for (int o = 0; o < scene->object_count(); ++o) {
    s.face_colors.push_back(scene->object_mesh(o).face_colors.data());
    const SurfaceMaterial& material = scene->material(o);
    s.object_ir_diffuse.push_back(
        static_cast<float>(material.ir_albedo * (1.0 - material.specularity)));
    s.object_ir_specular.push_back(static_cast<float>(material.specularity));
    s.object_subsurface_m.push_back(static_cast<float>(material.subsurface_mm / 1000.0));
    s.any_subsurface = s.any_subsurface || material.subsurface_mm > 0;
    s.face_ir_diffuse.emplace_back();
    if (material.colour_contrast > 0) {
      const TriangleMesh& mesh = scene->object_mesh(o);
      std::vector<float>& faces = s.face_ir_diffuse.back();
      faces.resize(mesh.face_count());
      for (int f = 0; f < mesh.face_count(); ++f) {
        const int brightest =
            std::max({mesh.face_colors(f, 0), mesh.face_colors(f, 1), mesh.face_colors(f, 2)});
        faces[f] = static_cast<float>(
            s.object_ir_diffuse.back() *
            ((1.0 - material.colour_contrast) + material.colour_contrast * brightest / 255.0));
      }
    }
    s.moving.push_back(scene->is_moving(o));
    s.moving_clusters.push_back(s.moving.back() ? ClusterBounds(scene->object_mesh(o), 3)
                                                : std::vector<Bounds3>());
  }
  // The IR camera sits at -ir_camera_offset along the colour camera's x axis, the projector a
  // baseline further along +x from the IR camera.
  const Rigid3 color_T_ir(Eigen::Quaterniond::Identity(),
                          Eigen::Vector3d(-options.ir_camera_offset, 0, 0));
  s.color_view.intrinsics = options.intrinsics;
  s.color_view.world_T_view = world_T_camera;
  s.color_view.needs_color = true;
  s.ir_grid = options.registered && options.mode == SensorMode::kStructuredLight &&
              options.structured_light.match_on_ir_grid;
  if (options.registered && !s.ir_grid) {
    s.color_view.needs_occlusion = true;
    if (options.missing.projector_shadow) {
      s.color_view.occluder_sources.push_back(-options.ir_camera_offset +
                                              options.calibration.baseline);
      s.color_view.occluder_bits.push_back(internal::kProjectorShadowBit);
    }
    if (options.missing.ir_camera_occlusion && options.ir_camera_offset != 0) {
      s.color_view.occluder_sources.push_back(-options.ir_camera_offset);
      s.color_view.occluder_bits.push_back(internal::kIrCameraBit);
    }
  } else {
    s.ir_view.intrinsics = options.ir_intrinsics;
    s.ir_view.world_T_view = world_T_camera * color_T_ir;
    s.ir_view.needs_occlusion = true;
    if (options.missing.projector_shadow) {
      s.ir_view.occluder_sources.push_back(options.calibration.baseline);
      s.ir_view.occluder_bits.push_back(internal::kProjectorShadowBit);
    }
  }

  for (int i = 0; i < 256; ++i) {
    s.srgb_to_linear[i] = static_cast<float>(SrgbToLinear(i / 255.0));
  }
  s.linear_to_srgb.resize(kEncodeSteps + 1);
  for (int i = 0; i <= kEncodeSteps; ++i) {
    s.linear_to_srgb[i] = static_cast<uint8_t>(std::lround(
        std::clamp(LinearToSrgb(static_cast<double>(i) / kEncodeSteps), 0.0, 1.0) * 255));
  }
  Eigen::Vector3d light(options.color.light_x, options.color.light_y, options.color.light_z);
  light.normalize();
  for (int c = 0; c < 3; ++c) s.light[c] = static_cast<float>(light[c]);
  s.ambient = static_cast<float>(options.color.ambient);
  s.diffuse = static_cast<float>(options.color.diffuse);
  s.background = static_cast<uint8_t>(options.color.background_gray);
  s.disparity_scale =
      static_cast<float>(options.calibration.ir_focal_length * options.calibration.baseline);
  s.lateral_cross.resize(kCosSteps + 1);
  s.drop.resize(kCosSteps + 1);
  s.grazing_sigma.resize(kCosSteps + 1);
  const double from = options.missing.grazing_from_deg * std::numbers::pi / 180.0;
  const double to = options.missing.grazing_to_deg * std::numbers::pi / 180.0;
  for (int i = 0; i <= kCosSteps; ++i) {
    // The step's cosine at its centre (the last step is cos = 1 exactly).
    const double c = std::min(1.0, (i + 0.5) / kCosSteps);
    const double theta = std::acos(c);
    const double sigma_l = options.lateral.Sigma(theta);
    // P(N(0, sigma_L) > 0.5 px): the offset rounds to at least one pixel towards the neighbour.
    s.lateral_cross[i] =
        sigma_l > 0 ? static_cast<float>(0.5 * std::erfc(0.5 / (sigma_l * std::sqrt(2.0)))) : 0.0f;
    const double grazing = std::clamp((theta - from) / (to - from), 0.0, 1.0);
    const double speckle = options.missing.speckle_probability;
    s.drop[i] = static_cast<float>(grazing + speckle - grazing * speckle);
    // The grazing term of sigma_z without its 1 / sqrt(z) factor.
    s.grazing_sigma[i] =
        static_cast<float>(options.axial.Sigma(1.0, theta) - options.axial.Sigma(1.0, 0.0));
  }
  while (s.flat_step > 0 && s.grazing_sigma[s.flat_step - 1] == 0.0f &&
         s.drop[s.flat_step - 1] == s.drop[kCosSteps]) {
    --s.flat_step;
  }
  s.color_alias = ColorAliasTable(options.color, &s.color_slot_bits);
  s.ShadeStaticFaces();
  if (options.mode == SensorMode::kStructuredLight) {
    s.match_view().needs_ir = true;
    // Nearer than min_depth nothing matches (the device's range); 0.8 min_depth leaves room
    // for the noise.
    const PinholeIntrinsics& k = s.match_view().intrinsics;
    s.speckle = std::make_unique<internal::SpeckleMatcher>(
        options.structured_light, k.width, k.height,
        options.calibration.ir_focal_length * options.calibration.baseline /
            (0.8 * options.min_depth));
  }
}

KinectSensor::~KinectSensor() = default;

bool KinectSensor::SetVectorKernels(bool enabled) {
  const bool avx512 = UseAvx512Default(), avx2 = internal::UseAvx2Default();
  UseAvx512().store(enabled && avx512);
  internal::UseAvx2().store(enabled && avx2);
  return enabled && (avx512 || avx2);
}

void KinectSensor::Render(int index, RenderMode mode, RgbdFrame* frame) {
  Impl& s = *impl_;
  const uint64_t rays_before = s.scene->rays_cast();
  s.UpdateGeometry(s.color_view, mode);
  if (!s.options.registered || s.ir_grid) s.UpdateGeometry(s.ir_view, mode);
  const auto t0 = Clock::now();
  s.Output(index, frame);
  s.timings.noise += Seconds(t0, Clock::now());
  s.timings.frames += 1;
  s.timings.rays += s.scene->rays_cast() - rays_before;
}

RgbdFrame KinectSensor::Render(int index, RenderMode mode) {
  RgbdFrame frame;
  Render(index, mode, &frame);
  return frame;
}

Rigid3 KinectSensor::world_T_depth_camera() const { return impl_->depth_view().world_T_view; }
const PinholeIntrinsics& KinectSensor::depth_intrinsics() const {
  return impl_->depth_view().intrinsics;
}
const PinholeIntrinsics& KinectSensor::color_intrinsics() const {
  return impl_->color_view.intrinsics;
}
Rigid3 KinectSensor::color_T_depth() const { return impl_->ColorTDepth(); }
const Rigid3& KinectSensor::world_T_camera() const { return impl_->world_T_camera; }
const KinectSensorOptions& KinectSensor::options() const { return impl_->options; }
void KinectSensor::KeepMissingCauses(bool keep) {
  if (keep) {
    impl_->last_causes.assign(impl_->depth_view().intrinsics.pixel_count(), MissingCause::kValid);
  } else {
    impl_->last_causes.clear();
  }
}
std::span<const MissingCause> KinectSensor::missing_causes() const { return impl_->last_causes; }
const SensorTimings& KinectSensor::timings() const { return impl_->timings; }
void KinectSensor::ResetTimings() { impl_->timings = SensorTimings(); }

SensorTimings& SensorTimings::operator+=(const SensorTimings& other) {
  cast += other.cast;
  shade += other.shade;
  restore += other.restore;
  occlusion += other.occlusion;
  noise += other.noise;
  frames += other.frames;
  rays += other.rays;
  pixels_recast += other.pixels_recast;
  return *this;
}

void RenderFrames(std::span<const SensorWorker> workers, int first, int count, RenderMode mode,
                  const std::function<void(const RgbdFrame&)>& consume) {
  if (workers.empty()) throw std::logic_error("RenderFrames: no workers");
  for (const SensorWorker& w : workers) {
    if (w.sensor == nullptr || !w.pose_scene) {
      throw std::logic_error("RenderFrames: a worker without a sensor or pose_scene");
    }
  }
  if (count <= 0) return;
  // As many frames in flight as workers: one between rendering and consume never holds a worker,
  // so a free worker and a free frame buffer always exist when a frame reaches the render stage.
  const size_t tokens = workers.size();
  std::mutex mutex;
  std::vector<const SensorWorker*> free_workers;
  for (const SensorWorker& w : workers) free_workers.push_back(&w);
  std::vector<std::unique_ptr<RgbdFrame>> frames(tokens);
  std::vector<RgbdFrame*> free_frames;
  for (auto& f : frames) {
    f = std::make_unique<RgbdFrame>();
    free_frames.push_back(f.get());
  }
  struct Item {
    int index = 0;
    RgbdFrame* frame = nullptr;
  };
  int next = first;
  const int end = first + count;
  tbb::parallel_pipeline(
      tokens, tbb::make_filter<void, Item>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control&
                                                                                      control) {
                if (next == end) {
                  control.stop();
                  return Item{};
                }
                std::lock_guard<std::mutex> lock(mutex);
                Item item{next++, free_frames.back()};
                free_frames.pop_back();
                return item;
              }) & tbb::make_filter<Item, Item>(tbb::filter_mode::parallel, [&](Item item) {
                const SensorWorker* worker = nullptr;
                {
                  std::lock_guard<std::mutex> lock(mutex);
                  worker = free_workers.back();
                  free_workers.pop_back();
                }
                struct Release {
                  std::mutex& mutex;
                  std::vector<const SensorWorker*>& free;
                  const SensorWorker* worker;
                  ~Release() {
                    std::lock_guard<std::mutex> lock(mutex);
                    free.push_back(worker);
                  }
                } release{mutex, free_workers, worker};
                worker->pose_scene(item.index);
                worker->sensor->Render(item.index, mode, item.frame);
                return item;
              }) & tbb::make_filter<Item, void>(tbb::filter_mode::serial_in_order, [&](Item item) {
                consume(*item.frame);
                std::lock_guard<std::mutex> lock(mutex);
                free_frames.push_back(item.frame);
              }));
}

SensorTimings TotalTimings(std::span<const SensorWorker> workers) {
  SensorTimings total;
  for (const SensorWorker& w : workers) total += w.sensor->timings();
  return total;
}

}  // namespace mmh::sim
