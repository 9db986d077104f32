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
#include "core/simd.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define MMH_SENSOR_AVX512 1
#else
#define MMH_SENSOR_AVX512 0
#endif

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

// Tables indexed by the incidence cosine quantised to kCosSteps.
constexpr int kCosSteps = 1024;

double SrgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
double LinearToSrgb(double c) {
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}
constexpr int kEncodeSteps = 4096;

// The union of row intervals (overlapping or touching ones merged), ordered by row and column.
// Rows are few (an image's height), so the intervals are bucketed by row (a counting sort) and
// only each row's handful is sorted by column.
std::vector<PixelSpan> MergeRowIntervals(const std::vector<PixelSpan>& intervals) {
  std::vector<PixelSpan> spans;
  if (intervals.empty()) return spans;
  int row_min = intervals.front().row, row_max = row_min;
  for (const PixelSpan& s : intervals) {
    row_min = std::min(row_min, s.row);
    row_max = std::max(row_max, s.row);
  }
  std::vector<int> start(static_cast<size_t>(row_max - row_min) + 2, 0);
  for (const PixelSpan& s : intervals) ++start[s.row - row_min + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<PixelSpan> by_row(intervals.size());
  std::vector<int> next(start.begin(), start.end() - 1);
  for (const PixelSpan& s : intervals) by_row[next[s.row - row_min]++] = s;
  for (size_t r = 0; r + 1 < start.size(); ++r) {
    const auto first = by_row.begin() + start[r], last = by_row.begin() + start[r + 1];
    std::sort(first, last,
              [](const PixelSpan& x, const PixelSpan& y) { return x.first < y.first; });
    const size_t row_begin = spans.size();
    for (auto it = first; it != last; ++it) {
      if (spans.size() > row_begin && it->first <= spans.back().last + 1) {
        spans.back().last = std::max(spans.back().last, it->last);
      } else {
        spans.push_back(*it);
      }
    }
  }
  return spans;
}

// Boxes (object frame) bounding a mesh's triangles in up to 2^depth groups, split at the median
// along the longest axis of their centroids: a moving object's screen coverage is the union of
// its boxes' projections, much tighter than one box for a bent arm.
std::vector<Bounds3> ClusterBounds(const TriangleMesh& mesh, int depth) {
  std::vector<int> faces(mesh.face_count());
  std::iota(faces.begin(), faces.end(), 0);
  auto centroid = [&](int f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += mesh.vertices.row(mesh.faces(f, k)).transpose().cast<double>();
    return Eigen::Vector3d(c / 3.0);
  };
  std::vector<Bounds3> boxes;
  auto split = [&](auto&& self, std::vector<int>::iterator first, std::vector<int>::iterator last,
                   int level) -> void {
    if (first == last) return;
    if (level == depth || last - first < 16) {
      Bounds3 box;
      for (auto it = first; it != last; ++it) {
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d p =
              mesh.vertices.row(mesh.faces(*it, k)).transpose().template cast<double>();
          box.min = box.min.cwiseMin(p);
          box.max = box.max.cwiseMax(p);
        }
      }
      boxes.push_back(box);
      return;
    }
    Bounds3 spread;
    for (auto it = first; it != last; ++it) {
      const Eigen::Vector3d c = centroid(*it);
      spread.min = spread.min.cwiseMin(c);
      spread.max = spread.max.cwiseMax(c);
    }
    int axis = 0;
    (spread.max - spread.min).maxCoeff(&axis);
    auto middle = first + (last - first) / 2;
    std::nth_element(first, middle, last,
                     [&](int a, int b) { return centroid(a)[axis] < centroid(b)[axis]; });
    self(self, first, middle, level + 1);
    self(self, middle, last, level + 1);
  };
  split(split, faces.begin(), faces.end(), 0);
  return boxes;
}

// Adds to each image row v the columns u whose pixel centre (u, v) lies in a convex polygon
// (image coordinates, in order around it), widened by kCoverMargin px on every side: a camera
// ray meets what projects into the polygon only through such a centre. The margin covers the
// rounding of single-precision rays (about 1e-4 px here), with room to spare.
constexpr double kCoverMargin = 0.05;
void CoverConvexPolygon(const std::vector<Eigen::Vector2d>& polygon, int width, int height,
                        std::vector<PixelSpan>* rows) {
  double y_min = 1e300, y_max = -1e300;
  for (const Eigen::Vector2d& p : polygon) {
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
  }
  const int v0 = std::max(0, static_cast<int>(std::ceil(y_min - kCoverMargin)));
  const int v1 = std::min(height - 1, static_cast<int>(std::floor(y_max + kCoverMargin)));
  if (v0 > v1) return;
  // Per row v the x extent of the polygon within the band [v - margin, v + margin]: each edge
  // contributes its x at the ends of its part inside the band (x linear in y along the edge; the
  // slope is computed once per edge, not once per row).
  const size_t n = polygon.size();
  std::vector<double> x_min(v1 - v0 + 1, 1e300), x_max(v1 - v0 + 1, -1e300);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % n];
    const double dy = b.y() - a.y();
    const double edge_y_min = std::min(a.y(), b.y()), edge_y_max = std::max(a.y(), b.y());
    const int first = std::max(v0, static_cast<int>(std::ceil(edge_y_min - kCoverMargin)));
    const int last = std::min(v1, static_cast<int>(std::floor(edge_y_max + kCoverMargin)));
    const double slope = dy == 0.0 ? 0.0 : (b.x() - a.x()) / dy;
    for (int v = first; v <= last; ++v) {
      double xa, xb;
      if (dy == 0.0) {
        xa = a.x();
        xb = b.x();
      } else {
        const double lo = std::max(edge_y_min, v - kCoverMargin);
        const double hi = std::min(edge_y_max, v + kCoverMargin);
        xa = a.x() + (lo - a.y()) * slope;
        xb = a.x() + (hi - a.y()) * slope;
      }
      double& row_min = x_min[v - v0];
      double& row_max = x_max[v - v0];
      row_min = std::min({row_min, xa, xb});
      row_max = std::max({row_max, xa, xb});
    }
  }
  for (int v = v0; v <= v1; ++v) {
    if (x_min[v - v0] > x_max[v - v0]) continue;
    const int u0 = std::max(0, static_cast<int>(std::ceil(x_min[v - v0] - kCoverMargin)));
    const int u1 = std::min(width - 1, static_cast<int>(std::floor(x_max[v - v0] + kCoverMargin)));
    if (u0 > u1) continue;
    rows->push_back({v, u0, u1});
  }
}

// Convex hull of points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Everything the per-pixel depth model needs, as floats for the vector loops.
struct DepthParams {
  uint32_t key_a = 0, key_b = 0, key_c = 0;
  bool noise = true;
  bool quantise = true;
  float lattice = 0, raw_offset = 0;
  float edge_jump = 0, edge_probability = 0;
  float min_depth = 0, max_depth = 0, inverse_scale = 0;
  float axial_a = 0, axial_b = 0, axial_z0 = 0;
  float grazing_cos_limit = 0;
  const float* lateral_cross = nullptr;  // per cos step: P(the lateral offset crosses the edge)
  const float* drop = nullptr;           // per cos step: P(grazing or speckle dropout)
  const float* grazing_sigma = nullptr;  // per cos step: grazing term of sigma_z times sqrt(z)
  // From this cos step on, grazing_sigma is 0 and drop equals drop[kCosSteps].
  int flat_step = 0;
};

// Colour noise: the noisy byte of a value v is round(v + sigma_v g), clamped to [0, 255], with g
// standard normal and sigma_v^2 = read_noise^2 + shot_gain v. Its distribution is discrete, so it
// is sampled exactly, without drawing g, by Walker's alias method (Walker 1977, Vose 1991) from a
// table per value (ColorAliasTable): one 32-bit hash per byte picks a slot (low slot_bits bits)
// and a uniform (top kColorThresholdBits bits) compared with the slot's threshold.
struct ColorParams {
  uint32_t key = 0;
  int slot_bits = 0;
  const uint32_t* table = nullptr;  // 256 values by 2^slot_bits slots: threshold << 8 | alias
};
constexpr int kColorThresholdBits = 23;

// The alias tables of ColorParams for a colour model: per value v (256) 2^slot_bits slots, slot
// j >= 1 standing for the byte o = v - 2^(slot_bits - 1) + j (slot 0 has no mass), whose
// probability is that of round(v + sigma_v g) clamped to [0, 255] landing on o:
// Phi((o - v + 1/2) / sigma_v) - Phi((o - v - 1/2) / sigma_v), where the ends of the window (or 0
// and 255) take the whole tails beyond them. The window is the narrowest whose tails hold less
// than 1e-6 for every value (+-15 for the default model, 4.9 sigma at the brightest value;
// Box-Muller with 16-bit radii stops at 4.85 sigma). The masses are rounded to multiples of
// 2^-(slot_bits + kColorThresholdBits) (2^-28 for the default model) and split into slots by
// Vose's algorithm in integers, so that the table samples those masses exactly. Entry: threshold
// (0 .. 2^kColorThresholdBits) << 8 | alias byte.
std::vector<uint32_t> ColorAliasTable(const ColorModel& color, int* slot_bits) {
  auto sigma_of = [&](int v) {
    // Beyond 1e6 the bytes are 0 or 255 alike to 1e-4; keeps the arithmetic finite.
    return std::min(1e6, std::sqrt(color.read_noise * color.read_noise + color.shot_gain * v));
  };
  // Upper tail of the standard normal, accurate far out (no cancellation).
  auto upper = [](double x) { return 0.5 * std::erfc(x / std::numbers::sqrt2); };
  const double sigma_max = sigma_of(255);
  int bits = 1;
  while (bits < 9 && sigma_max > 0 && 2 * upper(((1 << (bits - 1)) - 0.5) / sigma_max) >= 1e-6) {
    ++bits;
  }
  *slot_bits = bits;
  const int slots = 1 << bits;
  const int64_t fair = int64_t{1} << kColorThresholdBits;
  // 64 entries of padding: the permute lookups of ColorRowAvx512 load 64 entries from a row.
  std::vector<uint32_t> table((static_cast<size_t>(256) << bits) + 64);
  std::vector<double> p(slots);
  std::vector<int64_t> mass(slots);
  std::vector<int> small, large;
  for (int v = 0; v < 256; ++v) {
    const double sigma = sigma_of(v);
    const int first = v - slots / 2;
    double total = 0;
    for (int j = 0; j < slots; ++j) {
      const int o = first + j;
      p[j] = 0;
      if (j == 0 || o < 0 || o > 255) continue;
      const double inf = std::numeric_limits<double>::infinity();
      // The byte's interval of v + sigma g.
      const double a = (o == 0 || j == 1) ? -inf : o - v - 0.5;
      const double b = (o == 255 || j == slots - 1) ? inf : o - v + 0.5;
      if (sigma == 0) {
        p[j] = (a < 0 && b > 0) ? 1.0 : 0.0;
      } else if (a >= 0) {
        p[j] = upper(a / sigma) - upper(b / sigma);
      } else if (b <= 0) {
        p[j] = upper(-b / sigma) - upper(-a / sigma);
      } else {
        p[j] = 1.0 - upper(-a / sigma) - upper(b / sigma);
      }
      total += p[j];
    }
    int64_t assigned = 0;
    int mode = 0;
    for (int j = 0; j < slots; ++j) {
      mass[j] = std::llround(p[j] / total * static_cast<double>(fair * slots));
      assigned += mass[j];
      if (mass[j] > mass[mode]) mode = j;
    }
    mass[mode] += fair * slots - assigned;  // exactly the whole
    uint32_t* entries = &table[static_cast<size_t>(v) << bits];
    small.clear();
    large.clear();
    for (int j = 0; j < slots; ++j) {
      entries[j] = static_cast<uint32_t>(std::clamp(first + j, 0, 255));
      (mass[j] < fair ? small : large).push_back(j);
    }
    while (!small.empty() && !large.empty()) {
      const int j = small.back();
      small.pop_back();
      const int l = large.back();
      entries[j] = static_cast<uint32_t>(mass[j]) << 8 | static_cast<uint32_t>(first + l);
      mass[l] -= fair - mass[j];
      if (mass[l] < fair) {
        large.pop_back();
        small.push_back(l);
      }
    }
    // In integers the rest hold exactly one slot's share each.
    for (const std::vector<int>* rest : {&small, &large}) {
      for (int j : *rest) entries[j] |= static_cast<uint32_t>(fair) << 8;
    }
  }
  return table;
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
inline uint32_t CounterHash(uint32_t key, uint32_t counter) {
  return Mix32((counter * 0x9E3779B9u) ^ key);
}

// Box-Muller (1958) from a 32-bit hash: radius sqrt(-2 ln u1) with u1 = (bits 16-31 + 1/2) / 2^16
// (tails to 4.85 sigma), angle q pi/2 + x with the quadrant q = bits 14-15 and x uniform in
// (-pi/4, pi/4) from bits 0-13. Returns the two independent standard normals r cos and r sin.
// ln, sin and cos are evaluated here with IEEE operations only (+, *, /, sqrt and fused
// multiply-add, all correctly rounded; no libm approximations, whose vector variants may round
// differently): ln m = 2 atanh((m - 1) / (m + 1)) on m in [sqrt(1/2), sqrt(2)) (series to s^9,
// error < 1e-9), sin and cos by their Taylor series to x^9 and x^10 on |x| <= pi/4 (error
// < 3e-10), Horner steps as std::fma. The AVX-512 kernels repeat these operations in the same
// order (std::fma and vfmadd round alike).
constexpr float kLn2 = 0.693147180559945309f;
constexpr float kSqrt2 = 1.41421356237309505f;
constexpr float kHalfPi = 1.57079632679489662f;

inline float LnUnit(float u) {
  const auto bits = std::bit_cast<uint32_t>(u);
  int e = static_cast<int>(bits >> 23) - 127;
  float m = std::bit_cast<float>((bits & 0x007fffffu) | 0x3f800000u);
  const bool high = m >= kSqrt2;
  m = high ? m * 0.5f : m;
  e = high ? e + 1 : e;
  const float s = (m - 1.0f) / (m + 1.0f);
  const float s2 = s * s;
  float series = std::fma(s2, 1.0f / 9, 1.0f / 7);
  series = std::fma(s2, series, 1.0f / 5);
  series = std::fma(s2, series, 1.0f / 3);
  series = std::fma(s2, series, 1.0f);
  return std::fma(static_cast<float>(e), kLn2, (2.0f * s) * series);
}

inline void BoxMuller(uint32_t h, float* c, float* s) {
  const float u1 = (static_cast<float>(static_cast<int>(h >> 16)) + 0.5f) * (1.0f / 65536.0f);
  const float r = std::sqrt(-2.0f * LnUnit(u1));
  const uint32_t q = (h >> 14) & 3u;
  const float t = (static_cast<float>(static_cast<int>(h & 0x3fffu)) + 0.5f) * (1.0f / 16384.0f);
  const float x = (t - 0.5f) * kHalfPi;
  const float x2 = x * x;
  float sin_x = std::fma(x2, 1.0f / 362880, -1.0f / 5040);
  sin_x = std::fma(x2, sin_x, 1.0f / 120);
  sin_x = std::fma(x2, sin_x, -1.0f / 6);
  sin_x = std::fma(x * x2, sin_x, x);
  float cos_x = std::fma(x2, -1.0f / 3628800, 1.0f / 40320);
  cos_x = std::fma(x2, cos_x, -1.0f / 720);
  cos_x = std::fma(x2, cos_x, 1.0f / 24);
  cos_x = std::fma(x2, cos_x, -1.0f / 2);
  cos_x = std::fma(x2, cos_x, 1.0f);
  // (cos, sin) of q pi/2 + x.
  const float a = (q & 1u) ? sin_x : cos_x;
  const float b = (q & 1u) ? cos_x : sin_x;
  const float cos_angle = ((q == 1u) | (q == 2u)) ? -a : a;
  const float sin_angle = (q >= 2u) ? -b : b;
  *c = r * cos_angle;
  *s = r * sin_angle;
}

inline int CosStep(float cos_incidence) {
  const int step = static_cast<int>(cos_incidence * static_cast<float>(kCosSteps));
  return step < kCosSteps ? step : kCosSteps;
}

// One pixel of the depth model after the lateral step: axial noise (g: a standard normal), the
// disparity lattice, range and random dropouts (h: bits 0-15 the dropout uniform). The vector
// loop and the scalar edge pass both call it: IEEE operations only, so both round alike.
template <bool kQuantise>
inline uint16_t DepthSample(const DepthParams& q, float z, float cos_incidence, bool keep,
                            uint32_t h, float g) {
  const int step = CosStep(cos_incidence);
  const float u_drop = static_cast<float>(static_cast<int>(h & 0xffffu)) * (1.0f / 65536.0f);
  // Pixels that see nothing get a harmless depth so that the arithmetic stays finite.
  z = keep ? z : 1.0f;
  const float dz = z - q.axial_z0;
  const float sigma =
      std::fma(q.axial_b * dz, dz, q.axial_a) + q.grazing_sigma[step] / std::sqrt(z);
  const float zn = std::fma(sigma, g, z);
  const float raw = std::floor(q.raw_offset - q.lattice / zn + 0.5f);
  const float zq = q.lattice / (q.raw_offset - raw);
  // Selections written so that GCC if-converts them (the loop must vectorise).
  const bool on_lattice = !kQuantise || ((raw >= 0.0f) & (raw <= 2046.0f));
  float zo = zn;
  if constexpr (kQuantise) zo = zq;
  const bool valid =
      keep & (u_drop >= q.drop[step]) & on_lattice & (zo >= q.min_depth) & (zo <= q.max_depth);
  float units = std::floor(zo * q.inverse_scale + 0.5f);
  units = units < 65535.0f ? units : 65535.0f;
  units = valid ? units : 0.0f;
  return static_cast<uint16_t>(static_cast<int>(units));
}

// The random numbers of the depth pixels [first_pixel, first_pixel + n): pixels 2k and 2k + 1 take
// the two normals of the Box-Muller pair of counter k (key_c) and the low and high 16 bits of the
// key_b hash of k as their dropout uniforms.
MMH_SIMD_CLONES void DepthNoisePortable(const DepthParams& q, uint32_t first_pixel, int n,
                                        uint32_t* drop_bits, float* normal) {
  for (int i = 0; i < n;) {
    const uint32_t pixel = first_pixel + static_cast<uint32_t>(i);
    const uint32_t pair = pixel >> 1;
    float g[2];
    BoxMuller(CounterHash(q.key_c, pair), &g[0], &g[1]);
    const uint32_t h = CounterHash(q.key_b, pair);
    const uint32_t bits[2] = {h & 0xffffu, h >> 16};
    for (uint32_t b = pixel & 1u; b < 2 && i < n; ++b, ++i) {
      normal[i] = g[b];
      drop_bits[i] = bits[b];
    }
  }
}

// One pixel of the depth row's vector part: whether it is kept (something hit, not occluded) and
// an edge (largest 4-neighbour disparity difference above edge_jump), and its sample as if it
// were no edge.
template <bool kQuantise>
inline uint16_t DepthPixel(const DepthParams& q, float left, float d, float right, float up,
                           float down, float depth, float cos_incidence, uint8_t occluded,
                           uint32_t drop_bits, float g, uint8_t* edge) {
  const float jump = std::max(std::max(std::abs(d - left), std::abs(d - right)),
                              std::max(std::abs(d - up), std::abs(d - down)));
  // Disparity 0: nothing hit.
  const bool keep = (d != 0.0f) & (occluded == 0);
  *edge = static_cast<uint8_t>(keep & (jump > q.edge_jump));
  return DepthSample<kQuantise>(q, depth, cos_incidence, keep, drop_bits, g);
}

// A row of DepthPixel (outside the image counts as equal: no jump).
template <bool kQuantise>
MMH_SIMD_CLONES void DepthRowPortable(const DepthParams& q, const float* up, const float* row,
                                      const float* down, const float* depth,
                                      const float* cos_incidence, const uint8_t* occluded,
                                      const uint32_t* drop_bits, const float* normal, int first,
                                      int n, uint8_t* edge, uint16_t* out) {
  for (int i = first; i < n; ++i) {
    const float left = i > 0 ? row[i - 1] : row[i];
    const float right = i + 1 < n ? row[i + 1] : row[i];
    out[i] =
        DepthPixel<kQuantise>(q, left, row[i], right, up[i], down[i], depth[i], cos_incidence[i],
                              occluded[i], drop_bits[i], normal[i], &edge[i]);
  }
}

// Edge flags as bits: pixel u of a row is bit u % 64 of word u / 64 (#ceil(n / 64) words), so
// that the scalar edge pass visits only the rare edge pixels. ORs the 16 flags of pixels
// i .. i + 15 in (they lie in the row: no word past the row's last is touched).
inline void SetEdgeBits(uint64_t* words, int i, uint32_t flags16) {
  const int shift = i & 63;
  words[i >> 6] |= static_cast<uint64_t>(flags16) << shift;
  if (shift > 48) words[(i >> 6) + 1] |= static_cast<uint64_t>(flags16) >> (64 - shift);
}
// ORs the byte flags edge[first .. last) into the bits.
inline void PackEdgeBits(const uint8_t* edge, int first, int last, uint64_t* words) {
  for (int u = first; u < last; ++u) {
    words[u >> 6] |= static_cast<uint64_t>(edge[u] != 0) << (u & 63);
  }
}

// One colour byte from its hash h: slot j of value v stands for the byte v - 2^(slot_bits - 1) + j
// with probability threshold / 2^kColorThresholdBits, otherwise for its alias.
inline uint8_t NoisyColor(const ColorParams& p, uint8_t value, uint32_t h) {
  const uint32_t slot = h & ((1u << p.slot_bits) - 1u);
  const uint32_t entry = p.table[(static_cast<uint32_t>(value) << p.slot_bits) | slot];
  const uint32_t own = value + slot - (1u << (p.slot_bits - 1));
  return static_cast<uint8_t>((h >> (32 - kColorThresholdBits)) < (entry >> 8) ? own : entry);
}

// Colour noise on n bytes (RGB interleaved) of a row: byte i takes the hash of counter
// first_counter + i.
MMH_SIMD_CLONES void ColorRowPortable(const ColorParams& p, const uint8_t* in,
                                      uint32_t first_counter, int n, uint8_t* out) {
  for (int i = 0; i < n; ++i) {
    out[i] = NoisyColor(p, in[i], CounterHash(p.key, first_counter + static_cast<uint32_t>(i)));
  }
}

// A windowed occlusion scan (OcclusionWindowPortable) starts at the block holding the change's
// last (from the right) or first column, with the static scene's extremum of everything before
// that block in scan order as its carry.
template <bool kFromRight>
inline float WindowStart(const float* cached, int n, int first, int last, int* block) {
  const float infinity = std::numeric_limits<float>::infinity();
  *block = (kFromRight ? last : first) / 16;
  if constexpr (kFromRight) return (*block + 1) * 16 < n ? cached[(*block + 1) * 16] : infinity;
  return *block > 0 ? cached[16 * *block - 1] : -infinity;
}
// It ends after block [i, i + 16) once the block lies past the change and the running extremum
// equals the static scene's there.
template <bool kFromRight>
inline bool WindowEnds(const float* cached, int i, int first, int last, float carry) {
  if constexpr (kFromRight) return i <= first && carry == cached[i];
  return i + 15 >= last && carry == cached[i + 15];
}

// Hand-vectorised AVX-512 kernels (GCC 12 vectorises neither the bit manipulation nor floor
// well). They mirror the portable kernels above operation by operation (the same IEEE
// additions, multiplications, divisions, square roots, floors, comparisons and selections, in
// the same order; gathers load what the scalar code indexes), so frames do not depend on which
// of them runs (tested).
#if MMH_SENSOR_AVX512
// GCC 12's intrinsics headers trip -Wmaybe-uninitialized on their own undefined-vector helpers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define MMH_AVX512 __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl")))

MMH_AVX512 inline __m512i Mix32x16(__m512i x) {
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
  x = _mm512_mullo_epi32(x, _mm512_set1_epi32(0x7feb352d));
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 15));
  x = _mm512_mullo_epi32(x, _mm512_set1_epi32(static_cast<int>(0x846ca68bu)));
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
  return x;
}
// (first + j) * 0x9E3779B9 mod 2^32 for lanes j = 0 .. 15, as first * 0x9E3779B9 + j * 0x9E3779B9:
// the same words as CounterHash's product, for an addition instead of a vector multiply.
MMH_AVX512 inline __m512i ScrambledCounters(uint32_t first) {
  constexpr uint32_t kGolden = 0x9E3779B9u;
  return _mm512_add_epi32(
      _mm512_set1_epi32(static_cast<int>(first * kGolden)),
      _mm512_setr_epi32(0, static_cast<int>(kGolden), static_cast<int>(2 * kGolden),
                        static_cast<int>(3 * kGolden), static_cast<int>(4 * kGolden),
                        static_cast<int>(5 * kGolden), static_cast<int>(6 * kGolden),
                        static_cast<int>(7 * kGolden), static_cast<int>(8 * kGolden),
                        static_cast<int>(9 * kGolden), static_cast<int>(10 * kGolden),
                        static_cast<int>(11 * kGolden), static_cast<int>(12 * kGolden),
                        static_cast<int>(13 * kGolden), static_cast<int>(14 * kGolden),
                        static_cast<int>(15 * kGolden)));
}
// CounterHash of the counters behind ScrambledCounters(first).
MMH_AVX512 inline __m512i CounterHashx16(uint32_t key, __m512i scrambled) {
  return Mix32x16(_mm512_xor_si512(scrambled, _mm512_set1_epi32(static_cast<int>(key))));
}
// CounterHash of counters first .. first + 15.
MMH_AVX512 inline __m512i CounterHashx16(uint32_t key, uint32_t first) {
  return CounterHashx16(key, ScrambledCounters(first));
}
MMH_AVX512 inline __m512 Floorx16(__m512 x) {
  return _mm512_roundscale_ps(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}
MMH_AVX512 inline __m512 AbsDiff(__m512 a, __m512 b) { return _mm512_abs_ps(_mm512_sub_ps(a, b)); }
MMH_AVX512 inline __m512 Set(float x) { return _mm512_set1_ps(x); }
MMH_AVX512 inline __m512 Add(__m512 a, __m512 b) { return _mm512_add_ps(a, b); }
MMH_AVX512 inline __m512 Mul(__m512 a, __m512 b) { return _mm512_mul_ps(a, b); }
// a b + c rounded once, as std::fma in the portable kernels.
MMH_AVX512 inline __m512 Fma(__m512 a, __m512 b, __m512 c) { return _mm512_fmadd_ps(a, b, c); }
// Low 16 / bits 0-13 of h as floats.
MMH_AVX512 inline __m512 BitsToFloat(__m512i h, int mask) {
  return _mm512_cvtepi32_ps(_mm512_and_si512(h, _mm512_set1_epi32(mask)));
}

MMH_AVX512 inline __m512 LnUnitx16(__m512 u) {
  const __m512i bits = _mm512_castps_si512(u);
  __m512i e = _mm512_sub_epi32(_mm512_srli_epi32(bits, 23), _mm512_set1_epi32(127));
  __m512 m = _mm512_castsi512_ps(_mm512_or_si512(
      _mm512_and_si512(bits, _mm512_set1_epi32(0x007fffff)), _mm512_set1_epi32(0x3f800000)));
  const __mmask16 high = _mm512_cmp_ps_mask(m, Set(kSqrt2), _CMP_GE_OQ);
  m = _mm512_mask_mul_ps(m, high, m, Set(0.5f));
  e = _mm512_mask_add_epi32(e, high, e, _mm512_set1_epi32(1));
  const __m512 s = _mm512_div_ps(_mm512_sub_ps(m, Set(1.0f)), Add(m, Set(1.0f)));
  const __m512 s2 = Mul(s, s);
  __m512 series = Fma(s2, Set(1.0f / 9), Set(1.0f / 7));
  series = Fma(s2, series, Set(1.0f / 5));
  series = Fma(s2, series, Set(1.0f / 3));
  series = Fma(s2, series, Set(1.0f));
  return Fma(_mm512_cvtepi32_ps(e), Set(kLn2), Mul(Mul(Set(2.0f), s), series));
}

MMH_AVX512 inline void BoxMullerx16(__m512i h, __m512* c, __m512* s) {
  const __m512 u1 =
      Mul(Add(_mm512_cvtepi32_ps(_mm512_srli_epi32(h, 16)), Set(0.5f)), Set(1.0f / 65536.0f));
  const __m512 r = _mm512_sqrt_ps(Mul(Set(-2.0f), LnUnitx16(u1)));
  const __m512i q = _mm512_and_si512(_mm512_srli_epi32(h, 14), _mm512_set1_epi32(3));
  const __m512 t = Mul(Add(BitsToFloat(h, 0x3fff), Set(0.5f)), Set(1.0f / 16384.0f));
  const __m512 x = Mul(_mm512_sub_ps(t, Set(0.5f)), Set(kHalfPi));
  const __m512 x2 = Mul(x, x);
  __m512 sin_x = Fma(x2, Set(1.0f / 362880), Set(-1.0f / 5040));
  sin_x = Fma(x2, sin_x, Set(1.0f / 120));
  sin_x = Fma(x2, sin_x, Set(-1.0f / 6));
  sin_x = Fma(Mul(x, x2), sin_x, x);
  __m512 cos_x = Fma(x2, Set(-1.0f / 3628800), Set(1.0f / 40320));
  cos_x = Fma(x2, cos_x, Set(-1.0f / 720));
  cos_x = Fma(x2, cos_x, Set(1.0f / 24));
  cos_x = Fma(x2, cos_x, Set(-1.0f / 2));
  cos_x = Fma(x2, cos_x, Set(1.0f));
  const __mmask16 odd = _mm512_test_epi32_mask(q, _mm512_set1_epi32(1));
  const __m512 a = _mm512_mask_blend_ps(odd, cos_x, sin_x);
  const __m512 b = _mm512_mask_blend_ps(odd, sin_x, cos_x);
  const __mmask16 negate_cos = _mm512_cmpeq_epi32_mask(q, _mm512_set1_epi32(1)) |
                               _mm512_cmpeq_epi32_mask(q, _mm512_set1_epi32(2));
  const __mmask16 negate_sin = _mm512_cmpge_epi32_mask(q, _mm512_set1_epi32(2));
  const __m512 sign = Set(-0.0f);
  const __m512 cos_angle = _mm512_mask_xor_ps(a, negate_cos, a, sign);
  const __m512 sin_angle = _mm512_mask_xor_ps(b, negate_sin, b, sign);
  *c = Mul(r, cos_angle);
  *s = Mul(r, sin_angle);
}

// DepthNoisePortable, 16 pairs (32 pixels) at a time.
MMH_AVX512 void DepthNoiseAvx512(const DepthParams& q, uint32_t first_pixel, int n,
                                 uint32_t* drop_bits, float* normal) {
  const __m512i first_half =
      _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const __m512i second_half =
      _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  // An odd first pixel is the second of its pair: the portable code takes it.
  int i = static_cast<int>(first_pixel & 1u);
  if (i == 1 && n > 0) DepthNoisePortable(q, first_pixel, 1, drop_bits, normal);
  for (; i + 32 <= n; i += 32) {
    const uint32_t pair = (first_pixel + static_cast<uint32_t>(i)) >> 1;
    const __m512i counters = ScrambledCounters(pair);
    __m512 c, s;
    BoxMullerx16(CounterHashx16(q.key_c, counters), &c, &s);
    _mm512_storeu_ps(normal + i, _mm512_permutex2var_ps(c, first_half, s));
    _mm512_storeu_ps(normal + i + 16, _mm512_permutex2var_ps(c, second_half, s));
    const __m512i h = CounterHashx16(q.key_b, counters);
    const __m512i low = _mm512_and_si512(h, _mm512_set1_epi32(0xffff));
    const __m512i high = _mm512_srli_epi32(h, 16);
    _mm512_storeu_si512(drop_bits + i, _mm512_permutex2var_epi32(low, first_half, high));
    _mm512_storeu_si512(drop_bits + i + 16, _mm512_permutex2var_epi32(low, second_half, high));
  }
  if (i < n) {
    DepthNoisePortable(q, first_pixel + static_cast<uint32_t>(i), n - i, drop_bits + i, normal + i);
  }
}

// Pixels i .. i + 15 of DepthRowPortable, with their edge flags as bits i .. i + 15 of edge_bits
// (ORed in); `last`: pixel i + 15 ends the row (its right neighbour counts as equal).
template <bool kQuantise>
MMH_AVX512 inline void DepthBlockAvx512(const DepthParams& q, const float* up, const float* row,
                                        const float* down, const float* depth,
                                        const float* cos_incidence, const uint8_t* occluded,
                                        const uint32_t* drop_bits, const float* normal, int i,
                                        bool last, uint64_t* edge_bits, uint16_t* out) {
  const __m512 zero = _mm512_setzero_ps();
  const __m512 half = Set(0.5f);
  const __m512 d = _mm512_loadu_ps(row + i);
  const __m512 right =
      last ? _mm512_mask_loadu_ps(d, 0x7fff, row + i + 1) : _mm512_loadu_ps(row + i + 1);
  const __m512 jump = _mm512_max_ps(
      _mm512_max_ps(AbsDiff(d, _mm512_loadu_ps(row + i - 1)), AbsDiff(d, right)),
      _mm512_max_ps(AbsDiff(d, _mm512_loadu_ps(up + i)), AbsDiff(d, _mm512_loadu_ps(down + i))));
  const __m512i occ =
      _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(occluded + i)));
  const __mmask16 keep = _mm512_cmp_ps_mask(d, zero, _CMP_NEQ_UQ) &
                         _mm512_cmpeq_epi32_mask(occ, _mm512_setzero_si512());
  const __mmask16 is_edge = keep & _mm512_cmp_ps_mask(jump, Set(q.edge_jump), _CMP_GT_OQ);
  SetEdgeBits(edge_bits, i, is_edge);
  const __m512 g = _mm512_loadu_ps(normal + i);
  // DepthSample, lane-parallel.
  __m512i step = _mm512_cvttps_epi32(
      Mul(_mm512_loadu_ps(cos_incidence + i), Set(static_cast<float>(kCosSteps))));
  step = _mm512_min_epi32(step, _mm512_set1_epi32(kCosSteps));
  const __m512 u_drop =
      Mul(_mm512_cvtepi32_ps(_mm512_loadu_si512(drop_bits + i)), Set(1.0f / 65536.0f));
  const __m512 z = _mm512_mask_blend_ps(keep, Set(1.0f), _mm512_loadu_ps(depth + i));
  const __m512 dz = _mm512_sub_ps(z, Set(q.axial_z0));
  __m512 sigma = Fma(Mul(Set(q.axial_b), dz), dz, Set(q.axial_a));
  __m512 drop = Set(q.drop[kCosSteps]);
  // Steps from q.flat_step on have no grazing term (it is exactly 0, adding it changes nothing)
  // and the dropout probability of the last step: no table lookups when all lanes are there.
  if (_mm512_cmplt_epi32_mask(step, _mm512_set1_epi32(q.flat_step)) != 0) {
    sigma =
        Add(sigma, _mm512_div_ps(_mm512_i32gather_ps(step, q.grazing_sigma, 4), _mm512_sqrt_ps(z)));
    drop = _mm512_i32gather_ps(step, q.drop, 4);
  }
  const __m512 zn = Fma(sigma, g, z);
  __m512 zo = zn;
  __mmask16 valid = keep;
  if constexpr (kQuantise) {
    const __m512 lattice = Set(q.lattice), raw_offset = Set(q.raw_offset);
    const __m512 raw = Floorx16(Add(_mm512_sub_ps(raw_offset, _mm512_div_ps(lattice, zn)), half));
    zo = _mm512_div_ps(lattice, _mm512_sub_ps(raw_offset, raw));
    valid &= _mm512_cmp_ps_mask(raw, zero, _CMP_GE_OQ) &
             _mm512_cmp_ps_mask(raw, Set(2046.0f), _CMP_LE_OQ);
  }
  valid &= _mm512_cmp_ps_mask(u_drop, drop, _CMP_GE_OQ) &
           _mm512_cmp_ps_mask(zo, Set(q.min_depth), _CMP_GE_OQ) &
           _mm512_cmp_ps_mask(zo, Set(q.max_depth), _CMP_LE_OQ);
  __m512 units = Floorx16(Add(Mul(zo, Set(q.inverse_scale)), half));
  units = _mm512_min_ps(units, Set(65535.0f));  // (units < max) ? units : max, as scalar
  units = _mm512_maskz_mov_ps(valid, units);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i),
                      _mm512_cvtepi32_epi16(_mm512_cvttps_epi32(units)));
}

// A row of DepthBlockAvx512; edge: #n scratch for the portable code; edge_bits: zeroed.
template <bool kQuantise>
MMH_AVX512 void DepthRowAvx512(const DepthParams& q, const float* up, const float* row,
                               const float* down, const float* depth, const float* cos_incidence,
                               const uint8_t* occluded, const uint32_t* drop_bits,
                               const float* normal, int n, uint8_t* edge, uint64_t* edge_bits,
                               uint16_t* out) {
  if (n < 17) {
    DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                                0, n, edge, out);
    PackEdgeBits(edge, 0, n, edge_bits);
    return;
  }
  // Pixel 0 (no left neighbour): the portable code.
  DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              0, 1, edge, out);
  PackEdgeBits(edge, 0, 1, edge_bits);
  int i = 1;
  for (; i + 16 < n; i += 16) {
    DepthBlockAvx512<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                                i, false, edge_bits, out);
  }
  // The last 16 pixels (again where they overlap the previous block: same values).
  if (i < n) {
    DepthBlockAvx512<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                                n - 16, true, edge_bits, out);
  }
}

// The entries of `slot` in a table row of kSlots (32 or 64) slots, by permutes.
template <int kSlots>
MMH_AVX512 inline __m512i AliasLookup(const uint32_t* row, __m512i slot) {
  const auto* r = reinterpret_cast<const __m512i*>(row);
  const __m512i low =
      _mm512_permutex2var_epi32(_mm512_loadu_si512(r), slot, _mm512_loadu_si512(r + 1));
  if constexpr (kSlots <= 32) return low;
  const __m512i high =
      _mm512_permutex2var_epi32(_mm512_loadu_si512(r + 2), slot, _mm512_loadu_si512(r + 3));
  return _mm512_mask_blend_epi32(_mm512_test_epi32_mask(slot, _mm512_set1_epi32(32)), low, high);
}

// Where bytes repeat with period 3 (pixels of one colour, the common case on flat-shaded faces),
// the table rows of their three values are looked up by permutes (kSlots: 32 or 64 slots; 0: more,
// gathers only) instead of a gather, which costs about 24 cycles on Zen 4; both give the same
// entries. Sixteen pixels (48 bytes) of one colour share their three rows.
template <int kSlots>
MMH_AVX512 void ColorRowAvx512(const ColorParams& p, const uint8_t* in, uint32_t first_counter,
                               int n, uint8_t* out) {
  const int bits = p.slot_bits;
  const __m512i slot_mask = _mm512_set1_epi32((1 << bits) - 1);
  const __m512i half = _mm512_set1_epi32(1 << (bits - 1));
  const __m128i slot_shift = _mm_cvtsi32_si128(bits);
  // Lanes j = m (mod 3).
  constexpr __mmask16 kPhase[3] = {0x9249, 0x2492, 0x4924};
  auto load16 = [](const uint8_t* x)
                    MMH_AVX512 { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(x)); };
  auto row_of = [&](int i) MMH_AVX512 { return p.table + (static_cast<size_t>(in[i]) << bits); };
  // Bytes i .. i + 15 from their hashes and entries.
  auto finish = [&](int i, __m512i h, __m512i value, __m512i slot, __m512i entry) MMH_AVX512 {
    const __mmask16 take_own = _mm512_cmplt_epu32_mask(
        _mm512_srli_epi32(h, 32 - kColorThresholdBits), _mm512_srli_epi32(entry, 8));
    const __m512i own = _mm512_sub_epi32(_mm512_add_epi32(value, slot), half);
    // vpmovdb keeps the low byte: the alias of `entry`, or `own` (in [0, 255] when taken).
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                     _mm512_cvtepi32_epi8(_mm512_mask_blend_epi32(take_own, entry, own)));
  };
  // Bytes i .. i + 15 on their own.
  auto sixteen = [&](int i) MMH_AVX512 {
    const __m512i h = CounterHashx16(p.key, first_counter + static_cast<uint32_t>(i));
    const __m128i bytes = load16(in + i);
    const __m512i value = _mm512_cvtepu8_epi32(bytes);
    const __m512i slot = _mm512_and_si512(h, slot_mask);
    __m512i entry;
    if (kSlots != 0 && i + 19 <= n &&
        (_mm_cmpeq_epi8_mask(bytes, load16(in + i + 3)) & 0x1fff) == 0x1fff) {
      entry = AliasLookup<kSlots>(row_of(i), slot);
      entry = _mm512_mask_blend_epi32(kPhase[1], entry, AliasLookup<kSlots>(row_of(i + 1), slot));
      entry = _mm512_mask_blend_epi32(kPhase[2], entry, AliasLookup<kSlots>(row_of(i + 2), slot));
    } else {
      entry = _mm512_i32gather_epi32(_mm512_or_si512(_mm512_sll_epi32(value, slot_shift), slot),
                                     reinterpret_cast<const int*>(p.table), 4);
    }
    finish(i, h, value, slot, entry);
  };
  int i = 0;
  if constexpr (kSlots != 0) {
    for (; i + 51 <= n; i += 48) {
      __m128i bytes[3];
      bool run = true;
      for (int k = 0; k < 3; ++k) {
        bytes[k] = load16(in + i + 16 * k);
        const __mmask16 same = _mm_cmpeq_epi8_mask(bytes[k], load16(in + i + 16 * k + 3));
        run = run && (same | (k == 2 ? 0xe000 : 0)) == 0xffff;
      }
      if (!run) {
        for (int k = 0; k < 3; ++k) sixteen(i + 16 * k);
        continue;
      }
      const uint32_t* rows[3] = {row_of(i), row_of(i + 1), row_of(i + 2)};
      for (int k = 0; k < 3; ++k) {
        const int at = i + 16 * k;
        const __m512i h = CounterHashx16(p.key, first_counter + static_cast<uint32_t>(at));
        const __m512i slot = _mm512_and_si512(h, slot_mask);
        // Lane j of block k is byte 16 k + j, channel (k + j) mod 3.
        __m512i entry = AliasLookup<kSlots>(rows[0], slot);
        entry =
            _mm512_mask_blend_epi32(kPhase[(4 - k) % 3], entry, AliasLookup<kSlots>(rows[1], slot));
        entry =
            _mm512_mask_blend_epi32(kPhase[(5 - k) % 3], entry, AliasLookup<kSlots>(rows[2], slot));
        finish(at, h, _mm512_cvtepu8_epi32(bytes[k]), slot, entry);
      }
    }
  }
  for (; i + 16 <= n; i += 16) sixteen(i);
  ColorRowPortable(p, in + i, first_counter + static_cast<uint32_t>(i), n - i, out + i);
}
// The occlusion scans of OccludeRow, 16 pixels at a time: exclusive suffix minima (prefix
// maxima) inside a block by four shifted min (max) steps, carried across blocks. min and max are
// exact, so the flags equal the scalar scan's. n: a multiple of 16 (us padded with `none`).
// Lane j takes lane j + k (k > 0) or j + k (k < 0) of x; lanes shifted in are `fill`.
MMH_AVX512 inline __m512 ShiftLanes(__m512 x, __m512 fill, int k) {
  const __m512i xi = _mm512_castps_si512(x), fi = _mm512_castps_si512(fill);
  switch (k) {
    case 1:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(fi, xi, 1));
    case 2:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(fi, xi, 2));
    case 4:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(fi, xi, 4));
    case 8:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(fi, xi, 8));
    case -1:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(xi, fi, 15));
    case -2:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(xi, fi, 14));
    case -4:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(xi, fi, 12));
    default:
      return _mm512_castsi512_ps(_mm512_alignr_epi32(xi, fi, 8));  // -8
  }
}

template <bool kMin>
MMH_AVX512 inline __m512 Extremum(__m512 a, __m512 b) {
  return kMin ? _mm512_min_ps(a, b) : _mm512_max_ps(a, b);
}

// One direction of the occlusion scan: from the right (kFromRight: hidden iff not below the
// minimum of everything right of it) or from the left (hidden iff not above the maximum of
// everything left of it).
template <bool kFromRight>
MMH_AVX512 void OcclusionScanAvx512(const float* us, int n, uint8_t* occluded) {
  const float infinity = std::numeric_limits<float>::infinity();
  const __m512 none = Set(kFromRight ? infinity : -infinity);
  const int direction = kFromRight ? 1 : -1;
  __m512 carry = none;  // extremum of all blocks before this one in scan order
  for (int block = 0; block < n / 16; ++block) {
    const int i = kFromRight ? n - 16 - 16 * block : 16 * block;
    const __m512 x = _mm512_loadu_ps(us + i);
    // Lane j: extremum of the lanes before it in scan order.
    __m512 m = ShiftLanes(x, none, direction);
    for (int k : {1, 2, 4, 8}) m = Extremum<kFromRight>(m, ShiftLanes(m, none, direction * k));
    const __m512 bound = Extremum<kFromRight>(m, carry);
    const __mmask16 hidden = _mm512_cmp_ps_mask(x, bound, kFromRight ? _CMP_GE_OQ : _CMP_LE_OQ);
    const __m128i old = _mm_loadu_si128(reinterpret_cast<const __m128i*>(occluded + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(occluded + i),
                     _mm_or_si128(old, _mm512_cvtepi32_epi8(_mm512_maskz_set1_epi32(hidden, 1))));
    // The block's own extremum does not wait for the carry: the only chain from block to block
    // is one min (max), not a whole reduction.
    const float block_extremum = kFromRight ? _mm512_reduce_min_ps(x) : _mm512_reduce_max_ps(x);
    carry = Extremum<kFromRight>(carry, Set(block_extremum));
  }
}

// OcclusionWindowPortable (below), 16 pixels at a time.
template <bool kFromRight>
MMH_AVX512 int OcclusionWindowAvx512(const float* us, const float* cached, int n, int first,
                                     int last, uint8_t* flags) {
  const float infinity = std::numeric_limits<float>::infinity();
  const __m512 none = Set(kFromRight ? infinity : -infinity);
  const int direction = kFromRight ? 1 : -1;
  int block = 0;
  float carry_value = WindowStart<kFromRight>(cached, n, first, last, &block);
  __m512 carry = Set(carry_value);
  for (; kFromRight ? block >= 0 : block < n / 16; block += kFromRight ? -1 : 1) {
    const int i = 16 * block;
    const __m512 x = _mm512_loadu_ps(us + i);
    __m512 m = ShiftLanes(x, none, direction);
    for (int k : {1, 2, 4, 8}) m = Extremum<kFromRight>(m, ShiftLanes(m, none, direction * k));
    const __m512 bound = Extremum<kFromRight>(m, carry);
    const __mmask16 hidden = _mm512_cmp_ps_mask(x, bound, kFromRight ? _CMP_GE_OQ : _CMP_LE_OQ);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(flags + i),
                     _mm512_cvtepi32_epi8(_mm512_maskz_set1_epi32(hidden, 1)));
    carry_value = kFromRight ? std::min(carry_value, _mm512_reduce_min_ps(x))
                             : std::max(carry_value, _mm512_reduce_max_ps(x));
    carry = Set(carry_value);
    if (WindowEnds<kFromRight>(cached, i, first, last, carry_value)) return kFromRight ? i : i + 15;
  }
  return kFromRight ? 0 : n - 1;
}
#undef MMH_AVX512
#pragma GCC diagnostic pop
#endif  // MMH_SENSOR_AVX512

// The occlusion flags of one source over the part of a row that a change in columns
// [first, last] can affect (incremental frames), given the row's scan values now (us, #n, n a
// multiple of 16, padded with the source's `none`) and the inclusive extrema of the static
// scene's scan values (cached: from the right, cached[u] = min of us_static over u' >= u; from
// the left, max over u' <= u). Outside [first, last] the row equals the static scene, so the
// scan can start at the change with the cached extremum as its carry, and it can stop once its
// running extremum equals the cached one again beyond the change: from there on every pixel sees
// the same values as in the static scene and keeps its cached flag. Writes flags[u] for u in the
// window and returns the window's far end (from the right: its first pixel, from the left: its
// last; the near end is the start of the block holding `last` (`first`)). Blocks of 16 pixels,
// as the vector kernel (same window, same flags).
template <bool kFromRight>
int OcclusionWindowPortable(const float* us, const float* cached, int n, int first, int last,
                            uint8_t* flags) {
  int block = 0;
  float carry = WindowStart<kFromRight>(cached, n, first, last, &block);
  for (; kFromRight ? block >= 0 : block < n / 16; block += kFromRight ? -1 : 1) {
    const int i = 16 * block;
    if constexpr (kFromRight) {
      for (int u = i + 15; u >= i; --u) {
        flags[u] = static_cast<uint8_t>(us[u] >= carry);
        carry = std::min(carry, us[u]);
      }
    } else {
      for (int u = i; u < i + 16; ++u) {
        flags[u] = static_cast<uint8_t>(us[u] <= carry);
        carry = std::max(carry, us[u]);
      }
    }
    if (WindowEnds<kFromRight>(cached, i, first, last, carry)) return kFromRight ? i : i + 15;
  }
  return kFromRight ? 0 : n - 1;
}

// The flags and inclusive extrema of a whole row's scan for one source (the static scene's, for
// OcclusionWindowPortable): the same flags as the full scans of OccludeRow.
void OcclusionCacheRow(const float* us, int n, bool from_right, float* extremum, uint8_t* flags) {
  if (from_right) {
    float lowest = std::numeric_limits<float>::infinity();
    for (int u = n - 1; u >= 0; --u) {
      flags[u] = static_cast<uint8_t>(us[u] >= lowest);
      lowest = std::min(lowest, us[u]);
      extremum[u] = lowest;
    }
  } else {
    float highest = -std::numeric_limits<float>::infinity();
    for (int u = 0; u < n; ++u) {
      flags[u] = static_cast<uint8_t>(us[u] <= highest);
      highest = std::max(highest, us[u]);
      extremum[u] = highest;
    }
  }
}

bool UseAvx512Default() {
#if MMH_SENSOR_AVX512
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
  return false;
#endif
}
std::atomic<bool>& UseAvx512() {
  static std::atomic<bool> use{UseAvx512Default()};
  return use;
}

// OcclusionWindowPortable or its vector kernel (same window, same flags).
template <bool kFromRight>
int OcclusionWindow(const float* us, const float* cached, int n, int first, int last,
                    uint8_t* flags) {
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    return OcclusionWindowAvx512<kFromRight>(us, cached, n, first, last, flags);
  }
#endif
  return OcclusionWindowPortable<kFromRight>(us, cached, n, first, last, flags);
}

// One depth row: its random numbers (drop_bits, normal: #n scratch), then the pixels, with the
// edge flags as bits (edge_bits: #ceil(n / 64); edge: #n scratch).
template <bool kQuantise>
void DepthRow(const DepthParams& q, const float* up, const float* row, const float* down,
              const float* depth, const float* cos_incidence, const uint8_t* occluded,
              uint32_t first_pixel, int n, uint8_t* edge, uint64_t* edge_bits, uint32_t* drop_bits,
              float* normal, uint16_t* out) {
  std::fill_n(edge_bits, (n + 63) / 64, uint64_t{0});
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    DepthNoiseAvx512(q, first_pixel, n, drop_bits, normal);
    DepthRowAvx512<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              n, edge, edge_bits, out);
    return;
  }
#endif
  DepthNoisePortable(q, first_pixel, n, drop_bits, normal);
  DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              0, n, edge, out);
  PackEdgeBits(edge, 0, n, edge_bits);
}

void ColorRow(const ColorParams& p, const uint8_t* in, uint32_t first_counter, int n,
              uint8_t* out) {
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    if (p.slot_bits <= 5) {
      ColorRowAvx512<32>(p, in, first_counter, n, out);
    } else if (p.slot_bits == 6) {
      ColorRowAvx512<64>(p, in, first_counter, n, out);
    } else {
      ColorRowAvx512<0>(p, in, first_counter, n, out);
    }
    return;
  }
#endif
  ColorRowPortable(p, in, first_counter, n, out);
}

// f b / z of a packet's 16 lanes (lanes without a hit compute values nobody reads).
MMH_SIMD_CLONES void DisparityLanes(const float* __restrict depth, float scale,
                                    float* __restrict disparity) {
  for (int i = 0; i < HitPacket::kLanes; ++i) disparity[i] = scale / depth[i];
}

// Occlusion scan values of one row for a light source at x = source (see the header):
// u_s = u - shift * disparity; pixels that see nothing get `none` (never an extremum).
MMH_SIMD_CLONES void SourceColumns(const float* __restrict disparity, int n, float shift,
                                   float none, float* __restrict us) {
  for (int i = 0; i < n; ++i) {
    const float d = disparity[i];
    us[i] = d != 0.0f ? static_cast<float>(i) - shift * d : none;
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
  // Per-pixel geometry of one view, #pixels (colour #pixels by 3), row-major.
  struct Geometry {
    std::vector<float> depth;          // along the optical axis [m]; +inf where nothing was hit
    std::vector<float> disparity;      // IR disparity f b / z [px]; 0 where nothing was hit
    std::vector<float> cos_incidence;  // in [0, 1]; 0 where nothing was hit
    std::vector<uint8_t> color;        // shaded sRGB before noise (views that deliver colour)
    std::vector<uint8_t> occluded;     // hidden from an occluder source

    void Resize(int pixels, bool color_too) {
      depth.assign(pixels, std::numeric_limits<float>::infinity());
      disparity.assign(pixels, 0.0f);
      cos_incidence.assign(pixels, 0.0f);
      color.assign(color_too ? 3 * static_cast<size_t>(pixels) : 0, 0);
      occluded.assign(pixels, 0);
    }
  };

  // One camera's cached (static scene) and working geometry.
  struct View {
    PinholeIntrinsics intrinsics;
    Rigid3 world_T_view;
    bool needs_color = false;
    bool needs_occlusion = false;
    // x positions of the light sources whose occlusion makes pixels missing, in this view's frame.
    std::vector<double> occluder_sources;
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
          color_(view.needs_color ? view.current.color.data() : nullptr) {}

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
            continue;
          }
          depth[p] = packet.depth[i];
          disparity[p] = lane_disparity[i];
          cos_incidence[p] = packet.cos_incidence[i];
          if (color != nullptr) s_.Shade(packet, i, color + 3 * p);
        }
      }
    }

   private:
    const Impl& s_;
    int width_;
    bool hits_only_;
    float* depth_;
    float* disparity_;
    float* cos_incidence_;
    uint8_t* color_;
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

  View& depth_view() { return options.registered ? color_view : ir_view; }
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
                        std::vector<uint8_t> scan(width + 16);
                        for (size_t k = r.begin(); k != r.end(); ++k) {
                          const size_t row = static_cast<size_t>(rows[k]) * width;
                          OccludeRow(&g.disparity[row], width, fx, view.occluder_sources, us.data(),
                                     scan.data(), &g.occluded[row]);
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
              for (size_t k = 0; k < sources; ++k) any |= flags[k][u];
              occluded[u] = static_cast<uint8_t>(any & static_cast<uint8_t>(d[u] != 0.0f));
            }
            written = {change.row, lo, hi};
          }
        });
  }

  // us and scan: scratch of at least width + 16 entries.
  void OccludeRow(const float* disparity, int width, double fx, const std::vector<double>& sources,
                  float* us, uint8_t* scan, uint8_t* occluded) const {
    const int padded = (width + 15) / 16 * 16;
    const bool vector = UseAvx512().load(std::memory_order_relaxed) && MMH_SENSOR_AVX512;
    std::fill(scan, scan + padded, 0);
    for (double source_x : sources) {
      SourceRow(disparity, width, fx, source_x, us);
#if MMH_SENSOR_AVX512
      if (vector) {
        if (source_x > 0) {
          OcclusionScanAvx512<true>(us, padded, scan);
        } else {
          OcclusionScanAvx512<false>(us, padded, scan);
        }
        continue;
      }
#endif
      if (source_x > 0) {
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
    // Pixels that see nothing are not occluded (they are missing anyway).
    for (int u = 0; u < width; ++u) {
      occluded[u] = static_cast<uint8_t>(scan[u] & static_cast<uint8_t>(disparity[u] != 0.0f));
    }
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
      view.current.Resize(pixels, view.needs_color);
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

    // Depth and colour rows in one loop (one task wakes both cores once per frame).
    const int rows = std::max(dh, ch);
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, 16), [&](const tbb::blocked_range<int>& r) {
      std::vector<uint8_t> edge(dw);
      std::vector<uint64_t> edge_bits((dw + 63) / 64);
      std::vector<uint32_t> hash(dw);
      std::vector<float> normal(dw);
      for (int v = r.begin(); v != r.end(); ++v) {
        if (v < dh) {
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
}

KinectSensor::~KinectSensor() = default;

bool KinectSensor::SetVectorKernels(bool enabled) {
  const bool available = UseAvx512Default();
  UseAvx512().store(enabled && available);
  return enabled && available;
}

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
