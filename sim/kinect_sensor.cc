#include "sim/kinect_sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <boost/math/distributions/normal.hpp>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"
#include "core/simd.h"

namespace mmh::sim {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix; keyed by (seed,
// frame, pixel) it is a counter-based generator, so every pixel's noise is independent of the
// order in which pixels are processed.
inline uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Standard normal quantiles at the midpoints (i + 0.5) / 2^16, rescaled to unit variance: a
// 16-bit uniform indexes an exactly symmetric, unit-variance normal sample (tails to 4.3 sigma).
// Standard normal quantiles at the midpoints (i + 0.5) / 2^bits, rescaled to unit variance: a
// `bits`-bit uniform indexes an exactly symmetric, unit-variance normal sample.
std::vector<float> NormalQuantileTable(int bits) {
  const int size = 1 << bits;
  std::vector<double> q(size);
  boost::math::normal_distribution<double> normal;
  double sum_sq = 0.0;
  for (int i = 0; i < size / 2; ++i) {
    const double x = boost::math::quantile(normal, (i + 0.5) / size);
    q[i] = x;
    q[size - 1 - i] = -x;
    sum_sq += 2 * x * x;
  }
  const double scale = 1.0 / std::sqrt(sum_sq / size);
  std::vector<float> out(size);
  for (int i = 0; i < size; ++i) out[i] = static_cast<float>(q[i] * scale);
  return out;
}

// Depth noise: 2^16 entries (tails to 4.3 sigma).
const std::vector<float>& GaussTable() {
  static const std::vector<float> table = NormalQuantileTable(16);
  return table;
}

// Colour noise: 2^12 entries; 8-bit output makes finer quantiles pointless, and the 16 KB table
// stays in the L1 cache.
const std::vector<float>& SmallGaussTable() {
  static const std::vector<float> table = NormalQuantileTable(12);
  return table;
}

// Tables indexed by the incidence cosine quantised to kCosSteps.
constexpr int kCosSteps = 1024;

double SrgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
double LinearToSrgb(double c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}
constexpr int kEncodeSteps = 4096;

// Row spans covering the union of rectangles, merged per row.
struct Rect {
  int u0, v0, u1, v1;  // inclusive
};
std::vector<PixelSpan> SpansOfRects(const std::vector<Rect>& rects, int height) {
  std::vector<PixelSpan> spans;
  for (int v = 0; v < height; ++v) {
    std::vector<std::pair<int, int>> row;
    for (const Rect& r : rects) {
      if (v >= r.v0 && v <= r.v1) row.emplace_back(r.u0, r.u1);
    }
    if (row.empty()) continue;
    std::sort(row.begin(), row.end());
    int first = row[0].first;
    int last = row[0].second;
    for (size_t i = 1; i < row.size(); ++i) {
      if (row[i].first <= last + 1) {
        last = std::max(last, row[i].second);
      } else {
        spans.push_back({v, first, last});
        first = row[i].first;
        last = row[i].second;
      }
    }
    spans.push_back({v, first, last});
  }
  return spans;
}

// Everything the per-pixel depth model needs, as floats for the vector loops.
struct DepthParams {
  uint32_t key_a = 0, key_b = 0;
  const float* gauss = nullptr;
  bool noise = true;
  bool quantise = true;
  float lattice = 0, raw_offset = 0, disparity_scale = 0;
  float edge_jump = 0, edge_probability = 0, speckle = 0;
  float min_depth = 0, max_depth = 0, inverse_scale = 0;
  float axial_a = 0, axial_b = 0, axial_z0 = 0;
  float grazing_cos_limit = 0;
  const float* lateral_cross = nullptr;
  const float* grazing_missing = nullptr;
  const float* grazing_sigma = nullptr;
};

struct RowScratch {
  explicit RowScratch(int width)
      : hash_a(width), hash_b(width), jump(width), z(width), cos_incidence(width), keep(width) {}
  std::vector<uint32_t> hash_a, hash_b;
  std::vector<float> jump, z, cos_incidence;
  std::vector<uint32_t> keep;
};

// f b / z [px]; 0 where nothing was hit (z = +inf).
MMH_SIMD_CLONES void DisparityRow(const float* depth, int n, float scale, float* disparity) {
  for (int i = 0; i < n; ++i) disparity[i] = scale / depth[i];
}

// Chris Wellons' lowbias32: a bijective 32-bit mix with low bias. Keyed per frame and noise
// stream, applied to the scrambled pixel index, it is a counter-based generator whose 32-bit lanes
// vectorise on every x86-64 level.
inline uint32_t Mix32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

MMH_SIMD_CLONES void HashRow(uint32_t key, uint32_t first_pixel, int n, uint32_t* __restrict out) {
  for (int i = 0; i < n; ++i) {
    out[i] = Mix32(((first_pixel + static_cast<uint32_t>(i)) * 0x9E3779B9u) ^ key);
  }
}

// Largest disparity difference to the 4-neighbours (rows outside the image count as equal).
MMH_SIMD_CLONES void JumpRow(const float* up, const float* row, const float* down, int n,
                             float* jump) {
  for (int i = 1; i + 1 < n; ++i) {
    const float d = row[i];
    jump[i] = std::max(std::max(std::abs(d - row[i - 1]), std::abs(d - row[i + 1])),
                       std::max(std::abs(d - up[i]), std::abs(d - down[i])));
  }
  jump[0] = std::max(std::abs(row[0] - row[1]),
                     std::max(std::abs(row[0] - up[0]), std::abs(row[0] - down[0])));
  jump[n - 1] =
      std::max(std::abs(row[n - 1] - row[n - 2]),
               std::max(std::abs(row[n - 1] - up[n - 1]), std::abs(row[n - 1] - down[n - 1])));
}

// Axial noise, lattice, range and random dropouts of one row (the vector part of the model).
// hash_a: bits 0-15 lateral, 16-31 edge dropout (used by the scalar edge pass); hash_b: bits 0-15
// dropout, 16-31 the normal sample.
template <bool kQuantise>
MMH_SIMD_CLONES void NoisyDepthRow(const DepthParams& params, const float* __restrict z,
                                   const float* __restrict cos_incidence,
                                   const uint32_t* __restrict keep,
                                   const uint32_t* __restrict hash_b, int n,
                                   uint16_t* __restrict out) {
  const float* __restrict gauss = params.gauss;
  const float* __restrict grazing_missing = params.grazing_missing;
  const float* __restrict grazing_sigma = params.grazing_sigma;
  const float speckle = params.speckle;
  const float a = params.axial_a, b = params.axial_b, z0 = params.axial_z0;
  const float lattice = params.lattice, raw_offset = params.raw_offset;
  const float min_depth = params.min_depth, max_depth = params.max_depth;
  const float inverse_scale = params.inverse_scale;
  const float uniform = 1.0f / 65536.0f;
  for (int i = 0; i < n; ++i) {
    const uint32_t h = hash_b[i];
    int step = static_cast<int>(cos_incidence[i] * static_cast<float>(kCosSteps));
    step = step < kCosSteps ? step : kCosSteps;
    const float p_grazing = grazing_missing[step];
    const float u_drop = static_cast<float>(static_cast<int>(h & 0xffffu)) * uniform;
    const float p_drop = p_grazing + speckle - p_grazing * speckle;
    const float zi = z[i];
    const float dz = zi - z0;
    const float sigma = a + b * dz * dz + grazing_sigma[step] / std::sqrt(zi);
    const float zn = zi + sigma * gauss[h >> 16];
    const float raw = std::floor(raw_offset - lattice / zn + 0.5f);
    const float zq = lattice / (raw_offset - raw);
    // Selections written so that GCC if-converts them (the loop must vectorise).
    const bool on_lattice = !kQuantise || ((raw >= 0.0f) & (raw <= 2046.0f));
    float zo = zn;
    if constexpr (kQuantise) zo = zq;
    const bool valid =
        (keep[i] != 0) & (u_drop >= p_drop) & on_lattice & (zo >= min_depth) & (zo <= max_depth);
    float units = std::floor(zo * inverse_scale + 0.5f);
    units = units < 65535.0f ? units : 65535.0f;
    units = valid ? units : 0.0f;
    out[i] = static_cast<uint16_t>(static_cast<int>(units));
  }
}

// Colour noise: sigma^2 = read^2 + gain * value per channel; `in` and `out` are #n by 3.
MMH_SIMD_CLONES void ColorRow(const uint8_t* __restrict in, const uint32_t* __restrict hash_a,
                              const uint32_t* __restrict hash_b, int n,
                              const float* __restrict sigma, const float* __restrict gauss,
                              uint8_t* __restrict out) {
  for (int i = 0; i < n; ++i) {
    const uint32_t index[3] = {hash_a[i] & 0xfffu, (hash_a[i] >> 12) & 0xfffu,
                               (hash_a[i] >> 24) | ((hash_b[i] & 0xfu) << 8)};
    for (int c = 0; c < 3; ++c) {
      const uint8_t value = in[3 * i + c];
      float noisy = static_cast<float>(value) + sigma[value] * gauss[index[c]];
      noisy = std::floor(noisy + 0.5f);
      noisy = noisy < 0.0f ? 0.0f : (noisy > 255.0f ? 255.0f : noisy);
      out[3 * i + c] = static_cast<uint8_t>(static_cast<int>(noisy));
    }
  }
}

}  // namespace

void ColorModel::Validate(const std::string& prefix) const {
  const double norm = std::sqrt(light_x * light_x + light_y * light_y + light_z * light_z);
  if (!std::isfinite(norm) || norm == 0) {
    ThrowBadValue(prefix + ".light_x/y/z",
                  "(" + FormatNumber(light_x) + ", " + FormatNumber(light_y) + ", " +
                      FormatNumber(light_z) + ")",
                  "a finite non-zero direction");
  }
  RequireNonNegative(ambient, prefix + ".ambient");
  RequireNonNegative(diffuse, prefix + ".diffuse");
  if (background_gray < 0 || background_gray > 255) {
    ThrowBadValue(prefix + ".background_gray", std::to_string(background_gray),
                  "an 8-bit value in [0, 255]");
  }
  RequireNonNegative(read_noise, prefix + ".read_noise", "(8-bit units)");
  RequireNonNegative(shot_gain, prefix + ".shot_gain", "(8-bit units)");
}

void MissingDataModel::Validate(const std::string& prefix) const {
  RequireNonNegative(edge_jump_px, prefix + ".edge_jump_px", "px");
  RequireProbability(edge_probability, prefix + ".edge_probability");
  if (!std::isfinite(grazing_from_deg) || !std::isfinite(grazing_to_deg) || grazing_from_deg < 0 ||
      grazing_to_deg > 90 || grazing_from_deg >= grazing_to_deg) {
    ThrowBadValue(prefix + ".grazing_from_deg/grazing_to_deg",
                  FormatNumber(grazing_from_deg) + " / " + FormatNumber(grazing_to_deg),
                  "0 <= from < to <= 90 degrees");
  }
  RequireProbability(speckle_probability, prefix + ".speckle_probability");
}

void KinectSensorOptions::Validate(const std::string& prefix) const {
  intrinsics.Validate(prefix + ".intrinsics");
  ir_intrinsics.Validate(prefix + ".ir_intrinsics");
  if (!std::isfinite(ir_camera_offset) || std::abs(ir_camera_offset) > 1.0) {
    ThrowBadValue(prefix + ".ir_camera_offset", FormatNumber(ir_camera_offset),
                  "an offset in [-1, 1] m (Kinect v1: 0.025)");
  }
  calibration.Validate(prefix + ".calibration");
  if (!std::isfinite(min_depth) || min_depth <= 0) {
    ThrowBadValue(prefix + ".min_depth", FormatNumber(min_depth), "a depth > 0 m");
  }
  if (!std::isfinite(max_depth) || max_depth <= min_depth || max_depth > 13.0) {
    ThrowBadValue(prefix + ".max_depth", FormatNumber(max_depth),
                  "a depth above min_depth (" + FormatNumber(min_depth) +
                      " m) and at most 13 m (65535 depth units)");
  }
  axial.Validate(prefix + ".axial");
  lateral.Validate(prefix + ".lateral");
  missing.Validate(prefix + ".missing");
  color.Validate(prefix + ".color");
  if (!std::isfinite(frame_rate) || frame_rate <= 0 || frame_rate > 1000) {
    ThrowBadValue(prefix + ".frame_rate", FormatNumber(frame_rate), "a rate in (0, 1000] Hz");
  }
}

struct KinectSensor::Impl {
  // One camera's cached and working geometry.
  struct View {
    PinholeIntrinsics intrinsics;
    Rigid3 world_T_view;
    bool needs_color = false;
    bool needs_occlusion = false;
    // x positions of the light sources whose occlusion makes pixels missing, in this view's frame.
    std::vector<double> occluder_sources;
    HitBuffer static_hits, hits;
    std::vector<uint8_t> static_color, color;  // #pixels by 3, pre-noise sRGB
    std::vector<uint8_t> static_occluded, occluded;
    bool cached = false;
    bool all_dirty = false;  // the working buffers differ from the cache anywhere
    std::vector<PixelSpan> dirty;
  };

  KinectSensorOptions options;
  const RayScene* scene = nullptr;
  Rigid3 world_T_camera;
  View color_view, ir_view;
  SensorTimings timings;
  std::vector<const uint8_t*> face_colors;  // per object
  std::vector<bool> moving;
  // Lookup tables.
  std::array<float, 256> srgb_to_linear{};
  std::vector<uint8_t> linear_to_srgb;   // kEncodeSteps + 1
  std::array<float, 256> color_sigma{};  // per 8-bit value
  std::vector<float> lateral_cross;      // per cos step: P(offset rounds across the edge)
  std::vector<float> grazing_missing;    // per cos step
  std::vector<float> grazing_sigma;      // per cos step, times 1/sqrt(z) at use
  std::vector<float> disparity;          // per pixel of the depth view, this frame

  View& depth_view() { return options.registered ? color_view : ir_view; }
  Rigid3 ColorTDepth() { return color_view.world_T_view.Inverse() * depth_view().world_T_view; }

  // One row of the depth image: discontinuities, lateral noise at edges (scalar, edge pixels
  // only), then the vector part.
  static void DepthRow(const DepthParams& q, const View& dv, const float* disparity, int v, int w,
                       int h, RowScratch* s, uint16_t* out) {
    const size_t row = static_cast<size_t>(v) * w;
    const float* d = disparity + row;
    const float* up = v > 0 ? d - w : d;
    const float* down = v + 1 < h ? d + w : d;
    const float* depth = &dv.hits.depth[row];
    const float* cos_incidence = &dv.hits.cos_incidence[row];
    const uint8_t* occluded = &dv.occluded[row];
    std::copy_n(depth, w, s->z.data());
    std::copy_n(cos_incidence, w, s->cos_incidence.data());
    for (int u = 0; u < w; ++u) s->keep[u] = std::isfinite(depth[u]) && !occluded[u];
    if (!q.noise) {
      for (int u = 0; u < w; ++u) {
        float z = depth[u];
        bool keep = s->keep[u] && cos_incidence[u] >= q.grazing_cos_limit;
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
      return;
    }
    HashRow(q.key_a, static_cast<uint32_t>(row), w, s->hash_a.data());
    HashRow(q.key_b, static_cast<uint32_t>(row), w, s->hash_b.data());
    JumpRow(up, d, down, w, s->jump.data());
    const float uniform = 1.0f / 65536.0f;
    for (int u = 0; u < w; ++u) {
      if (!(s->jump[u] > q.edge_jump) || !s->keep[u]) continue;
      const uint32_t hash = s->hash_a[u];
      // The neighbour across the largest jump.
      size_t across = row + u;
      float largest = -1.0f;
      auto consider = [&](bool inside, size_t p) {
        if (!inside) return;
        const float j = std::abs(disparity[p] - d[u]);
        if (j > largest) {
          largest = j;
          across = p;
        }
      };
      consider(u > 0, row + u - 1);
      consider(u + 1 < w, row + u + 1);
      consider(v > 0, row + u - w);
      consider(v + 1 < h, row + u + w);
      const int step = std::min(kCosSteps, static_cast<int>(cos_incidence[u] * kCosSteps));
      const float u_lateral = static_cast<float>(hash & 0xffffu) * uniform;
      const float u_edge = static_cast<float>((hash >> 16) & 0xffffu) * uniform;
      // Lateral noise: the edge moves by the rounded N(0, sigma_L) offset; towards the neighbour
      // across the edge in half of the cases where it rounds to one pixel or more.
      if (u_lateral < q.lateral_cross[step] && std::isfinite(dv.hits.depth[across])) {
        s->z[u] = dv.hits.depth[across];
        s->cos_incidence[u] = dv.hits.cos_incidence[across];
      }
      if (u_edge < q.edge_probability) s->keep[u] = 0;
    }
    // Pixels that see nothing get a harmless depth so that the vector loop stays finite.
    for (int u = 0; u < w; ++u) {
      if (!s->keep[u]) s->z[u] = 1.0f;
    }
    if (q.quantise) {
      NoisyDepthRow<true>(q, s->z.data(), s->cos_incidence.data(), s->keep.data(), s->hash_b.data(),
                          w, out);
    } else {
      NoisyDepthRow<false>(q, s->z.data(), s->cos_incidence.data(), s->keep.data(),
                           s->hash_b.data(), w, out);
    }
  }

  void Shade(View& view, std::span<const PixelSpan> spans) {
    const int width = view.intrinsics.width;
    Eigen::Vector3f light(options.color.light_x, options.color.light_y, options.color.light_z);
    light.normalize();
    const float ambient = static_cast<float>(options.color.ambient);
    const float diffuse = static_cast<float>(options.color.diffuse);
    const auto background = static_cast<uint8_t>(options.color.background_gray);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, spans.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t k = r.begin(); k != r.end(); ++k) {
            const PixelSpan& span = spans[k];
            for (int u = span.first; u <= span.last; ++u) {
              const size_t p = static_cast<size_t>(span.row) * width + u;
              uint8_t* out = &view.color[3 * p];
              const uint32_t object = view.hits.object[p];
              if (object == kNoObject) {
                out[0] = out[1] = out[2] = background;
                continue;
              }
              const uint8_t* albedo = face_colors[object] + 3 * view.hits.face[p];
              const Eigen::Vector3f n(view.hits.normal[3 * p], view.hits.normal[3 * p + 1],
                                      view.hits.normal[3 * p + 2]);
              const float light_factor = ambient + diffuse * std::max(0.0f, n.dot(light));
              for (int c = 0; c < 3; ++c) {
                const float linear = std::min(1.0f, srgb_to_linear[albedo[c]] * light_factor);
                out[c] = linear_to_srgb[static_cast<int>(linear * kEncodeSteps + 0.5f)];
              }
            }
          }
        });
  }

  // Marks pixels of rows [row_first, row_last] hidden from any occluder source: a row scan per
  // source (see the header).
  void Occlude(View& view, const std::vector<int>& rows) {
    const int width = view.intrinsics.width;
    const double fx = view.intrinsics.fx;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 8),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t k = r.begin(); k != r.end(); ++k) {
                          const size_t row = static_cast<size_t>(rows[k]) * width;
                          const float* depth = &view.hits.depth[row];
                          uint8_t* occluded = &view.occluded[row];
                          std::fill(occluded, occluded + width, 0);
                          for (double source_x : view.occluder_sources) {
                            const auto shift = static_cast<float>(fx * source_x);
                            if (source_x > 0) {
                              float lowest = std::numeric_limits<float>::infinity();
                              for (int u = width - 1; u >= 0; --u) {
                                if (!std::isfinite(depth[u])) continue;
                                const float us = static_cast<float>(u) - shift / depth[u];
                                if (us >= lowest) occluded[u] = 1;
                                lowest = std::min(lowest, us);
                              }
                            } else {
                              float highest = -std::numeric_limits<float>::infinity();
                              for (int u = 0; u < width; ++u) {
                                if (!std::isfinite(depth[u])) continue;
                                const float us = static_cast<float>(u) - shift / depth[u];
                                if (us <= highest) occluded[u] = 1;
                                highest = std::max(highest, us);
                              }
                            }
                          }
                        }
                      });
  }

  std::vector<PixelSpan> MovingSpans(const View& view) const {
    const Rigid3 view_T_world = view.world_T_view.Inverse();
    const PinholeIntrinsics& k = view.intrinsics;
    std::vector<Rect> rects;
    for (int o = 0; o < scene->object_count(); ++o) {
      if (!moving[o]) continue;
      const Bounds3 bounds = scene->WorldBounds(o);
      if (bounds.empty()) continue;
      double u_min = 1e300, u_max = -1e300, v_min = 1e300, v_max = -1e300;
      bool behind = false;
      for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d w((corner & 1) ? bounds.max.x() : bounds.min.x(),
                                (corner & 2) ? bounds.max.y() : bounds.min.y(),
                                (corner & 4) ? bounds.max.z() : bounds.min.z());
        const Eigen::Vector3d c = view_T_world * w;
        if (c.z() < 1e-3) {
          behind = true;
          break;
        }
        const Eigen::Vector2d px = k.Project(c);
        u_min = std::min(u_min, px.x());
        u_max = std::max(u_max, px.x());
        v_min = std::min(v_min, px.y());
        v_max = std::max(v_max, px.y());
      }
      if (behind) return FullImageSpans(k);
      // One pixel of margin: a pixel whose ray grazes the bounds is still cast.
      const int u0 = std::max(0, static_cast<int>(std::floor(u_min)) - 1);
      const int u1 = std::min(k.width - 1, static_cast<int>(std::ceil(u_max)) + 1);
      const int v0 = std::max(0, static_cast<int>(std::floor(v_min)) - 1);
      const int v1 = std::min(k.height - 1, static_cast<int>(std::ceil(v_max)) + 1);
      if (u0 > u1 || v0 > v1) continue;
      rects.push_back({u0, v0, u1, v1});
    }
    return SpansOfRects(rects, k.height);
  }

  // Restores the cached static geometry (and colour) of `spans` in the working buffers.
  static void RestoreSpans(std::span<const PixelSpan> spans, View& view) {
    const int width = view.intrinsics.width;
    for (const PixelSpan& s : spans) {
      const size_t a = static_cast<size_t>(s.row) * width + s.first;
      const size_t n = s.last - s.first + 1;
      std::copy_n(&view.static_hits.depth[a], n, &view.hits.depth[a]);
      std::copy_n(&view.static_hits.object[a], n, &view.hits.object[a]);
      std::copy_n(&view.static_hits.face[a], n, &view.hits.face[a]);
      std::copy_n(&view.static_hits.cos_incidence[a], n, &view.hits.cos_incidence[a]);
      std::copy_n(&view.static_hits.normal[3 * a], 3 * n, &view.hits.normal[3 * a]);
      if (view.needs_color) std::copy_n(&view.static_color[3 * a], 3 * n, &view.color[3 * a]);
    }
  }

  void UpdateGeometry(View& view, RenderMode mode) {
    const PinholeIntrinsics& k = view.intrinsics;
    const auto full = FullImageSpans(k);
    std::vector<int> all_rows(k.height);
    for (int v = 0; v < k.height; ++v) all_rows[v] = v;
    auto t0 = Clock::now();
    if (!view.cached) {
      view.hits.Resize(k.pixel_count());
      view.color.assign(3 * static_cast<size_t>(k.pixel_count()), 0);
      view.occluded.assign(k.pixel_count(), 0);
      scene->Cast(k, view.world_T_view, full, RayScene::Target::kStatic, &view.hits);
      auto t1 = Clock::now();
      timings.cast += Seconds(t0, t1);
      if (view.needs_color) Shade(view, full);
      auto t2 = Clock::now();
      timings.shade += Seconds(t1, t2);
      if (view.needs_occlusion) Occlude(view, all_rows);
      timings.occlusion += Seconds(t2, Clock::now());
      view.static_hits = view.hits;
      view.static_color = view.color;
      view.static_occluded = view.occluded;
      view.cached = true;
      view.all_dirty = false;
      view.dirty.clear();
      t0 = Clock::now();
    }
    std::vector<PixelSpan> spans;
    RayScene::Target target = RayScene::Target::kMoving;
    if (mode == RenderMode::kFull) {
      spans = full;
      target = RayScene::Target::kAll;
    } else {
      spans = MovingSpans(view);
      // Back to the cache where the previous frame differed from it.
      if (view.all_dirty) {
        RestoreSpans(full, view);
      } else {
        RestoreSpans(view.dirty, view);
      }
    }
    // Rows whose occlusion can differ from the cache: those touched now or last frame.
    std::vector<char> row_dirty(k.height, view.all_dirty || mode == RenderMode::kFull);
    for (const PixelSpan& s : view.dirty) row_dirty[s.row] = 1;
    for (const PixelSpan& s : spans) row_dirty[s.row] = 1;
    // Other rows keep the cached occlusion: their depth equals the cache.
    std::vector<int> rows;
    for (int v = 0; v < k.height; ++v) {
      if (row_dirty[v]) rows.push_back(v);
    }
    auto t1 = Clock::now();
    scene->Cast(k, view.world_T_view, spans, target, &view.hits);
    auto t2 = Clock::now();
    if (view.needs_color) Shade(view, spans);
    auto t3 = Clock::now();
    if (view.needs_occlusion) Occlude(view, rows);
    auto t4 = Clock::now();
    timings.cast += Seconds(t1, t2);
    timings.shade += Seconds(t0, t1) + Seconds(t2, t3);
    timings.occlusion += Seconds(t3, t4);
    uint64_t recast = 0;
    for (const PixelSpan& s : spans) recast += s.last - s.first + 1;
    timings.pixels_recast += recast;
    view.all_dirty = mode == RenderMode::kFull;
    view.dirty = std::move(spans);
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
    const uint64_t color_key = Mix64(frame_key ^ 0xD1B54A32D192ED03ULL);
    q.gauss = GaussTable().data();
    q.noise = options.noise;
    q.quantise = options.quantise;
    q.lattice = static_cast<float>(options.calibration.lattice_constant());
    q.raw_offset = static_cast<float>(options.calibration.raw_offset);
    q.disparity_scale =
        static_cast<float>(options.calibration.ir_focal_length * options.calibration.baseline);
    q.edge_jump = static_cast<float>(options.missing.edge_jump_px);
    q.edge_probability = static_cast<float>(options.missing.edge_probability);
    q.speckle = static_cast<float>(options.missing.speckle_probability);
    q.min_depth = static_cast<float>(options.min_depth);
    q.max_depth = static_cast<float>(options.max_depth);
    q.inverse_scale = static_cast<float>(1.0 / kTumDepthScale);
    q.axial_a = static_cast<float>(options.axial.constant);
    q.axial_b = static_cast<float>(options.axial.quadratic);
    q.axial_z0 = static_cast<float>(options.axial.quadratic_origin);
    q.grazing_cos_limit =
        static_cast<float>(std::cos(options.missing.grazing_to_deg * std::numbers::pi / 180.0));
    q.lateral_cross = lateral_cross.data();
    q.grazing_missing = grazing_missing.data();
    q.grazing_sigma = grazing_sigma.data();
    const int dw = dk.width;
    const int dh = dk.height;
    disparity.resize(dk.pixel_count());

    // Disparity of every pixel first (its neighbours' are needed for the discontinuities).
    tbb::parallel_for(tbb::blocked_range<int>(0, dh, 16), [&](const tbb::blocked_range<int>& r) {
      for (int v = r.begin(); v != r.end(); ++v) {
        const size_t row = static_cast<size_t>(v) * dw;
        DisparityRow(&dv.hits.depth[row], dw, q.disparity_scale, &disparity[row]);
      }
    });
    tbb::parallel_for(tbb::blocked_range<int>(0, dh, 8), [&](const tbb::blocked_range<int>& r) {
      RowScratch scratch(dw);
      for (int v = r.begin(); v != r.end(); ++v) {
        DepthRow(q, dv, disparity.data(), v, dw, dh, &scratch,
                 &frame->depth[static_cast<size_t>(v) * dw]);
      }
    });

    const int cw = ck.width;
    tbb::parallel_for(
        tbb::blocked_range<int>(0, ck.height, 8), [&](const tbb::blocked_range<int>& r) {
          std::vector<uint32_t> hash_a(cw), hash_b(cw);
          for (int v = r.begin(); v != r.end(); ++v) {
            const size_t row = static_cast<size_t>(v) * cw;
            if (!options.noise) {
              std::copy_n(&cv.color[3 * row], 3 * cw, &frame->rgb[3 * row]);
              continue;
            }
            HashRow(static_cast<uint32_t>(color_key), static_cast<uint32_t>(row), cw,
                    hash_a.data());
            HashRow(static_cast<uint32_t>(color_key >> 32), static_cast<uint32_t>(row), cw,
                    hash_b.data());
            ColorRow(&cv.color[3 * row], hash_a.data(), hash_b.data(), cw, color_sigma.data(),
                     SmallGaussTable().data(), &frame->rgb[3 * row]);
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
    s.moving.push_back(scene->is_moving(o));
  }
  // The IR camera sits at -ir_camera_offset along the colour camera's x axis, the projector a
  // baseline further along +x from the IR camera.
  const Rigid3 color_T_ir(Eigen::Quaterniond::Identity(),
                          Eigen::Vector3d(-options.ir_camera_offset, 0, 0));
  s.color_view.intrinsics = options.intrinsics;
  s.color_view.world_T_view = world_T_camera;
  s.color_view.needs_color = true;
  if (options.registered) {
    s.color_view.needs_occlusion = true;
    if (options.missing.projector_shadow) {
      s.color_view.occluder_sources.push_back(-options.ir_camera_offset +
                                              options.calibration.baseline);
    }
    if (options.missing.ir_camera_occlusion && options.ir_camera_offset != 0) {
      s.color_view.occluder_sources.push_back(-options.ir_camera_offset);
    }
  } else {
    s.ir_view.intrinsics = options.ir_intrinsics;
    s.ir_view.world_T_view = world_T_camera * color_T_ir;
    s.ir_view.needs_occlusion = true;
    if (options.missing.projector_shadow) {
      s.ir_view.occluder_sources.push_back(options.calibration.baseline);
    }
  }

  for (int i = 0; i < 256; ++i) {
    s.srgb_to_linear[i] = static_cast<float>(SrgbToLinear(i / 255.0));
    s.color_sigma[i] = static_cast<float>(std::sqrt(
        options.color.read_noise * options.color.read_noise + options.color.shot_gain * i));
  }
  s.linear_to_srgb.resize(kEncodeSteps + 1);
  for (int i = 0; i <= kEncodeSteps; ++i) {
    s.linear_to_srgb[i] = static_cast<uint8_t>(std::lround(
        std::clamp(LinearToSrgb(static_cast<double>(i) / kEncodeSteps), 0.0, 1.0) * 255));
  }
  s.lateral_cross.resize(kCosSteps + 1);
  s.grazing_missing.resize(kCosSteps + 1);
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
    s.grazing_missing[i] = static_cast<float>(std::clamp((theta - from) / (to - from), 0.0, 1.0));
    // The grazing term of sigma_z without its 1 / sqrt(z) factor.
    s.grazing_sigma[i] =
        static_cast<float>(options.axial.Sigma(1.0, theta) - options.axial.Sigma(1.0, 0.0));
  }
}

KinectSensor::~KinectSensor() = default;

void KinectSensor::Render(int index, RenderMode mode, RgbdFrame* frame) {
  Impl& s = *impl_;
  const uint64_t rays_before = s.scene->rays_cast();
  s.UpdateGeometry(s.color_view, mode);
  if (!s.options.registered) s.UpdateGeometry(s.ir_view, mode);
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
const SensorTimings& KinectSensor::timings() const { return impl_->timings; }
void KinectSensor::ResetTimings() { impl_->timings = SensorTimings(); }

}  // namespace mmh::sim
