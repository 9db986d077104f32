#include "sim/kinect_sensor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <boost/math/distributions/normal.hpp>
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
  float lattice = 0, raw_offset = 0;
  float edge_jump = 0, edge_probability = 0;
  float min_depth = 0, max_depth = 0, inverse_scale = 0;
  float axial_a = 0, axial_b = 0, axial_z0 = 0;
  float grazing_cos_limit = 0;
  const float* lateral_cross = nullptr;  // per cos step: P(the lateral offset crosses the edge)
  const float* drop = nullptr;           // per cos step: P(grazing or speckle dropout)
  const float* grazing_sigma = nullptr;  // per cos step: grazing term of sigma_z times sqrt(z)
};

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

inline int CosStep(float cos_incidence) {
  const int step = static_cast<int>(cos_incidence * static_cast<float>(kCosSteps));
  return step < kCosSteps ? step : kCosSteps;
}

// One pixel of the depth model after the lateral step: axial noise, the disparity lattice, range
// and random dropouts. h: bits 0-15 the dropout uniform, 16-31 the normal sample. The vector loop
// and the scalar edge pass both call it: IEEE operations only, so both round alike.
template <bool kQuantise>
inline uint16_t DepthSample(const DepthParams& q, float z, float cos_incidence, bool keep,
                            uint32_t h) {
  const int step = CosStep(cos_incidence);
  const float u_drop = static_cast<float>(static_cast<int>(h & 0xffffu)) * (1.0f / 65536.0f);
  // Pixels that see nothing get a harmless depth so that the arithmetic stays finite.
  z = keep ? z : 1.0f;
  const float dz = z - q.axial_z0;
  const float sigma = q.axial_a + q.axial_b * dz * dz + q.grazing_sigma[step] / std::sqrt(z);
  const float zn = z + sigma * q.gauss[h >> 16];
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

// One pixel of the depth row's vector part: whether it is kept (something hit, not occluded) and
// an edge (largest 4-neighbour disparity difference above edge_jump), its noise hash, and its
// sample as if it were no edge.
template <bool kQuantise>
inline uint16_t DepthPixel(const DepthParams& q, float left, float d, float right, float up,
                           float down, float depth, float cos_incidence, uint8_t occluded,
                           uint32_t counter, uint8_t* edge, uint32_t* hash) {
  const float jump = std::max(std::max(std::abs(d - left), std::abs(d - right)),
                              std::max(std::abs(d - up), std::abs(d - down)));
  // Disparity 0: nothing hit.
  const bool keep = (d != 0.0f) & (occluded == 0);
  *edge = static_cast<uint8_t>(keep & (jump > q.edge_jump));
  const uint32_t h = CounterHash(q.key_b, counter);
  *hash = h;
  return DepthSample<kQuantise>(q, depth, cos_incidence, keep, h);
}

// A row of DepthPixel (n >= 2; outside the image counts as equal: no jump).
template <bool kQuantise>
MMH_SIMD_CLONES void DepthRowKernel(const DepthParams& params, const float* __restrict up,
                                    const float* __restrict row, const float* __restrict down,
                                    const float* __restrict depth,
                                    const float* __restrict cos_incidence,
                                    const uint8_t* __restrict occluded, uint32_t first_pixel, int n,
                                    uint8_t* __restrict edge, uint32_t* __restrict hash,
                                    uint16_t* __restrict out) {
  const DepthParams q = params;
  out[0] = DepthPixel<kQuantise>(q, row[0], row[0], row[1], up[0], down[0], depth[0],
                                 cos_incidence[0], occluded[0], first_pixel, &edge[0], &hash[0]);
  for (int i = 1; i + 1 < n; ++i) {
    out[i] = DepthPixel<kQuantise>(q, row[i - 1], row[i], row[i + 1], up[i], down[i], depth[i],
                                   cos_incidence[i], occluded[i],
                                   first_pixel + static_cast<uint32_t>(i), &edge[i], &hash[i]);
  }
  const int l = n - 1;
  out[l] = DepthPixel<kQuantise>(q, row[l - 1], row[l], row[l], up[l], down[l], depth[l],
                                 cos_incidence[l], occluded[l],
                                 first_pixel + static_cast<uint32_t>(l), &edge[l], &hash[l]);
}

// Colour noise on n bytes (RGB interleaved): sigma^2 = read^2 + gain * value per channel, one
// 12-bit normal index per byte from 16-bit halves of counter hashes.
MMH_SIMD_CLONES void ColorRowKernel(const uint8_t* __restrict in, uint32_t key,
                                    uint32_t first_counter, int n, const float* __restrict sigma,
                                    const float* __restrict gauss, uint16_t* __restrict index,
                                    uint8_t* __restrict out) {
  const int pairs = (n + 1) / 2;
  for (int k = 0; k < pairs; ++k) {
    const uint32_t h = CounterHash(key, first_counter + static_cast<uint32_t>(k));
    index[2 * k] = static_cast<uint16_t>(h & 0xfffu);
    index[2 * k + 1] = static_cast<uint16_t>((h >> 16) & 0xfffu);
  }
  for (int j = 0; j < n; ++j) {
    const uint8_t value = in[j];
    float noisy = static_cast<float>(value) + sigma[value] * gauss[index[j]];
    noisy = std::floor(noisy + 0.5f);
    noisy = noisy < 0.0f ? 0.0f : (noisy > 255.0f ? 255.0f : noisy);
    out[j] = static_cast<uint8_t>(static_cast<int>(noisy));
  }
}

// Hand-vectorised AVX-512 kernels: GCC 12 does not vectorise these loops well (no gathers at
// generic tuning, floor only with -fno-trapping-math). They mirror the portable kernels above
// operation by operation (the same IEEE additions, multiplications, divisions, square roots,
// floors and comparisons, in the same order; gathers load what the scalar code indexes), so
// frames do not depend on which of them runs (tested).
#if MMH_SENSOR_AVX512
#define MMH_AVX512 __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl")))

MMH_AVX512 inline __m512i Mix32x16(__m512i x) {
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
  x = _mm512_mullo_epi32(x, _mm512_set1_epi32(0x7feb352d));
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 15));
  x = _mm512_mullo_epi32(x, _mm512_set1_epi32(static_cast<int>(0x846ca68bu)));
  x = _mm512_xor_si512(x, _mm512_srli_epi32(x, 16));
  return x;
}
// CounterHash of counters first .. first + 15.
MMH_AVX512 inline __m512i CounterHashx16(uint32_t key, uint32_t first) {
  const __m512i counter =
      _mm512_add_epi32(_mm512_set1_epi32(static_cast<int>(first)),
                       _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
  return Mix32x16(_mm512_xor_si512(
      _mm512_mullo_epi32(counter, _mm512_set1_epi32(static_cast<int>(0x9E3779B9u))),
      _mm512_set1_epi32(static_cast<int>(key))));
}
MMH_AVX512 inline __m512 Floorx16(__m512 x) {
  return _mm512_roundscale_ps(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}
MMH_AVX512 inline __m512 AbsDiff(__m512 a, __m512 b) { return _mm512_abs_ps(_mm512_sub_ps(a, b)); }

template <bool kQuantise>
MMH_AVX512 void DepthRowAvx512(const DepthParams& q, const float* up, const float* row,
                               const float* down, const float* depth, const float* cos_incidence,
                               const uint8_t* occluded, uint32_t first_pixel, int n, uint8_t* edge,
                               uint32_t* hash, uint16_t* out) {
  // Pixel 0 and the tail that does not fill 16 lanes: the portable code.
  out[0] = DepthPixel<kQuantise>(q, row[0], row[0], row[1], up[0], down[0], depth[0],
                                 cos_incidence[0], occluded[0], first_pixel, &edge[0], &hash[0]);
  const __m512 zero = _mm512_setzero_ps();
  const __m512 one = _mm512_set1_ps(1.0f);
  const __m512 half = _mm512_set1_ps(0.5f);
  const __m512 edge_jump = _mm512_set1_ps(q.edge_jump);
  const __m512 cos_steps = _mm512_set1_ps(static_cast<float>(kCosSteps));
  const __m512i max_step = _mm512_set1_epi32(kCosSteps);
  const __m512 uniform = _mm512_set1_ps(1.0f / 65536.0f);
  const __m512 z0 = _mm512_set1_ps(q.axial_z0), a = _mm512_set1_ps(q.axial_a),
               b = _mm512_set1_ps(q.axial_b);
  const __m512 lattice = _mm512_set1_ps(q.lattice), raw_offset = _mm512_set1_ps(q.raw_offset);
  const __m512 raw_max = _mm512_set1_ps(2046.0f);
  const __m512 min_depth = _mm512_set1_ps(q.min_depth), max_depth = _mm512_set1_ps(q.max_depth);
  const __m512 inverse_scale = _mm512_set1_ps(q.inverse_scale);
  const __m512 units_max = _mm512_set1_ps(65535.0f);
  int i = 1;
  for (; i + 16 < n; i += 16) {
    const __m512 d = _mm512_loadu_ps(row + i);
    const __m512 jump = _mm512_max_ps(
        _mm512_max_ps(AbsDiff(d, _mm512_loadu_ps(row + i - 1)),
                      AbsDiff(d, _mm512_loadu_ps(row + i + 1))),
        _mm512_max_ps(AbsDiff(d, _mm512_loadu_ps(up + i)), AbsDiff(d, _mm512_loadu_ps(down + i))));
    const __m512i occ =
        _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(occluded + i)));
    const __mmask16 keep = _mm512_cmp_ps_mask(d, zero, _CMP_NEQ_UQ) &
                           _mm512_cmpeq_epi32_mask(occ, _mm512_setzero_si512());
    const __mmask16 is_edge = keep & _mm512_cmp_ps_mask(jump, edge_jump, _CMP_GT_OQ);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(edge + i),
                     _mm512_cvtepi32_epi8(_mm512_maskz_set1_epi32(is_edge, 1)));
    const __m512i h = CounterHashx16(q.key_b, first_pixel + static_cast<uint32_t>(i));
    _mm512_storeu_si512(hash + i, h);
    // DepthSample, lane-parallel.
    __m512i step =
        _mm512_cvttps_epi32(_mm512_mul_ps(_mm512_loadu_ps(cos_incidence + i), cos_steps));
    step = _mm512_min_epi32(step, max_step);
    const __m512 u_drop =
        _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_and_si512(h, _mm512_set1_epi32(0xffff))), uniform);
    const __m512 z = _mm512_mask_blend_ps(keep, one, _mm512_loadu_ps(depth + i));
    const __m512 dz = _mm512_sub_ps(z, z0);
    const __m512 sigma = _mm512_add_ps(
        _mm512_add_ps(a, _mm512_mul_ps(_mm512_mul_ps(b, dz), dz)),
        _mm512_div_ps(_mm512_i32gather_ps(step, q.grazing_sigma, 4), _mm512_sqrt_ps(z)));
    const __m512 g = _mm512_i32gather_ps(_mm512_srli_epi32(h, 16), q.gauss, 4);
    const __m512 zn = _mm512_add_ps(z, _mm512_mul_ps(sigma, g));
    __m512 zo = zn;
    __mmask16 valid = keep;
    if constexpr (kQuantise) {
      const __m512 raw =
          Floorx16(_mm512_add_ps(_mm512_sub_ps(raw_offset, _mm512_div_ps(lattice, zn)), half));
      zo = _mm512_div_ps(lattice, _mm512_sub_ps(raw_offset, raw));
      valid &=
          _mm512_cmp_ps_mask(raw, zero, _CMP_GE_OQ) & _mm512_cmp_ps_mask(raw, raw_max, _CMP_LE_OQ);
    }
    valid &= _mm512_cmp_ps_mask(u_drop, _mm512_i32gather_ps(step, q.drop, 4), _CMP_GE_OQ) &
             _mm512_cmp_ps_mask(zo, min_depth, _CMP_GE_OQ) &
             _mm512_cmp_ps_mask(zo, max_depth, _CMP_LE_OQ);
    __m512 units = Floorx16(_mm512_add_ps(_mm512_mul_ps(zo, inverse_scale), half));
    units = _mm512_min_ps(units, units_max);  // (units < max) ? units : max, as the scalar code
    units = _mm512_maskz_mov_ps(valid, units);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i),
                        _mm512_cvtepi32_epi16(_mm512_cvttps_epi32(units)));
  }
  for (; i < n; ++i) {
    const float right = i + 1 < n ? row[i + 1] : row[i];
    out[i] = DepthPixel<kQuantise>(q, row[i - 1], row[i], right, up[i], down[i], depth[i],
                                   cos_incidence[i], occluded[i],
                                   first_pixel + static_cast<uint32_t>(i), &edge[i], &hash[i]);
  }
}

MMH_AVX512 void ColorRowAvx512(const uint8_t* in, uint32_t key, uint32_t first_counter, int n,
                               const float* sigma, const float* gauss, uint16_t* index,
                               uint8_t* out) {
  const int pairs = (n + 1) / 2;
  int k = 0;
  for (; k + 16 <= pairs; k += 16) {
    // Two 12-bit indices per hash, as the portable kernel: index[2k] = h & 0xfff,
    // index[2k + 1] = (h >> 16) & 0xfff (little-endian 16-bit halves).
    const __m512i h = CounterHashx16(key, first_counter + static_cast<uint32_t>(k));
    _mm512_storeu_si512(index + 2 * k, _mm512_and_si512(h, _mm512_set1_epi32(0x0fff0fff)));
  }
  for (; k < pairs; ++k) {
    const uint32_t h = CounterHash(key, first_counter + static_cast<uint32_t>(k));
    index[2 * k] = static_cast<uint16_t>(h & 0xfffu);
    index[2 * k + 1] = static_cast<uint16_t>((h >> 16) & 0xfffu);
  }
  const __m512 half = _mm512_set1_ps(0.5f);
  const __m512 zero = _mm512_setzero_ps();
  const __m512 top = _mm512_set1_ps(255.0f);
  int j = 0;
  for (; j + 16 <= n; j += 16) {
    const __m512i value =
        _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + j)));
    const __m512i idx =
        _mm512_cvtepu16_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(index + j)));
    const __m512 noisy = _mm512_add_ps(
        _mm512_cvtepi32_ps(value),
        _mm512_mul_ps(_mm512_i32gather_ps(value, sigma, 4), _mm512_i32gather_ps(idx, gauss, 4)));
    __m512 r = Floorx16(_mm512_add_ps(noisy, half));
    // noisy < 0 ? 0 : (noisy > 255 ? 255 : noisy), as the portable kernel.
    r = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(r, top, _CMP_GT_OQ), r, top);
    r = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(r, zero, _CMP_LT_OQ), r, zero);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + j),
                     _mm512_cvtepi32_epi8(_mm512_cvttps_epi32(r)));
  }
  for (; j < n; ++j) {
    const uint8_t value = in[j];
    float noisy = static_cast<float>(value) + sigma[value] * gauss[index[j]];
    noisy = std::floor(noisy + 0.5f);
    noisy = noisy < 0.0f ? 0.0f : (noisy > 255.0f ? 255.0f : noisy);
    out[j] = static_cast<uint8_t>(static_cast<int>(noisy));
  }
}
#undef MMH_AVX512
#endif  // MMH_SENSOR_AVX512

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

template <bool kQuantise>
void DepthRow(const DepthParams& q, const float* up, const float* row, const float* down,
              const float* depth, const float* cos_incidence, const uint8_t* occluded,
              uint32_t first_pixel, int n, uint8_t* edge, uint32_t* hash, uint16_t* out) {
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    DepthRowAvx512<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, first_pixel, n,
                              edge, hash, out);
    return;
  }
#endif
  DepthRowKernel<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, first_pixel, n, edge,
                            hash, out);
}

void ColorRow(const uint8_t* in, uint32_t key, uint32_t first_counter, int n, const float* sigma,
              const float* gauss, uint16_t* index, uint8_t* out) {
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    ColorRowAvx512(in, key, first_counter, n, sigma, gauss, index, out);
    return;
  }
#endif
  ColorRowKernel(in, key, first_counter, n, sigma, gauss, index, out);
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
      const uint32_t write = hits_only_ ? packet.hit : packet.cast;
      for (int r = 0; r < HitPacket::kTile; ++r) {
        const int shift = r * HitPacket::kTile;
        const uint32_t row_write = (write >> shift) & 0xfu;
        if (row_write == 0) continue;
        const size_t base = static_cast<size_t>(packet.v0 + r) * width_ + packet.u0;
        if (row_write == 0xfu && ((packet.hit >> shift) & 0xfu) == 0xfu) {
          // Four hits side by side (the common case).
          for (int c = 0; c < HitPacket::kTile; ++c) {
            depth[base + c] = packet.depth[shift + c];
            disparity[base + c] = disparity_scale / packet.depth[shift + c];
            cos_incidence[base + c] = packet.cos_incidence[shift + c];
          }
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
          disparity[p] = disparity_scale / packet.depth[i];
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
  // Shading.
  float light[3] = {0, 0, 1};
  float ambient = 0, diffuse = 0;
  uint8_t background = 0;
  float disparity_scale = 0;  // f b [px m] of the IR camera
  // Lookup tables.
  std::array<float, 256> srgb_to_linear{};
  std::vector<uint8_t> linear_to_srgb;   // kEncodeSteps + 1
  std::array<float, 256> color_sigma{};  // per 8-bit value
  std::vector<float> lateral_cross;      // per cos step: P(offset rounds across the edge)
  std::vector<float> drop;               // per cos step: P(grazing or speckle dropout)
  std::vector<float> grazing_sigma;      // per cos step, times 1/sqrt(z) at use

  View& depth_view() { return options.registered ? color_view : ir_view; }
  Rigid3 ColorTDepth() { return color_view.world_T_view.Inverse() * depth_view().world_T_view; }

  // One row of the depth image: the vector part for every pixel, then, for edge pixels only,
  // the edge dropout and the lateral noise (an edge pixel takes the depth and incidence of its
  // neighbour across the largest jump).
  template <bool kQuantise>
  static void NoisyDepthRow(const DepthParams& q, const Geometry& g, int v, int w, int h,
                            uint8_t* edge, uint32_t* hash, uint16_t* out) {
    const size_t row = static_cast<size_t>(v) * w;
    const float* d = &g.disparity[row];
    const float* up = v > 0 ? d - w : d;
    const float* down = v + 1 < h ? d + w : d;
    if (w == 1) {
      out[0] = DepthPixel<kQuantise>(q, d[0], d[0], d[0], up[0], down[0], g.depth[row],
                                     g.cos_incidence[row], g.occluded[row],
                                     static_cast<uint32_t>(row), edge, hash);
    } else {
      DepthRow<kQuantise>(q, up, d, down, &g.depth[row], &g.cos_incidence[row], &g.occluded[row],
                          static_cast<uint32_t>(row), w, edge, hash, out);
    }
    const float uniform = 1.0f / 65536.0f;
    for (int u = 0; u < w; ++u) {
      // Edges are rare: skip eight pixels at a time.
      if (u % 8 == 0 && u + 8 <= w) {
        uint64_t word;
        std::memcpy(&word, edge + u, sizeof(word));
        if (word == 0) {
          u += 7;
          continue;
        }
      }
      if (!edge[u]) continue;
      const uint32_t hash_a = CounterHash(q.key_a, static_cast<uint32_t>(row + u));
      const float u_lateral = static_cast<float>(hash_a & 0xffffu) * uniform;
      const float u_edge = static_cast<float>((hash_a >> 16) & 0xffffu) * uniform;
      if (u_edge < q.edge_probability) {
        out[u] = 0;
        continue;
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
        out[u] = DepthSample<kQuantise>(q, g.depth[across], g.cos_incidence[across], true, hash[u]);
      }
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
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size(), 16),
                      [&](const tbb::blocked_range<size_t>& r) {
                        std::vector<float> us(width);
                        for (size_t k = r.begin(); k != r.end(); ++k) {
                          const size_t row = static_cast<size_t>(rows[k]) * width;
                          OccludeRow(&g.disparity[row], width, fx, view.occluder_sources, us.data(),
                                     &g.occluded[row]);
                        }
                      });
  }

  void OccludeRow(const float* disparity, int width, double fx, const std::vector<double>& sources,
                  float* us, uint8_t* occluded) const {
    std::fill(occluded, occluded + width, 0);
    for (double source_x : sources) {
      const auto shift = static_cast<float>(fx * source_x / disparity_scale);
      if (source_x > 0) {
        // Scanning from the source's side (+x): hidden iff not left of everything right of it.
        SourceColumns(disparity, width, shift, std::numeric_limits<float>::infinity(), us);
        float lowest = std::numeric_limits<float>::infinity();
        for (int u = width - 1; u >= 0; --u) {
          occluded[u] |= static_cast<uint8_t>(us[u] >= lowest);
          lowest = std::min(lowest, us[u]);
        }
      } else {
        SourceColumns(disparity, width, shift, -std::numeric_limits<float>::infinity(), us);
        float highest = -std::numeric_limits<float>::infinity();
        for (int u = 0; u < width; ++u) {
          occluded[u] |= static_cast<uint8_t>(us[u] <= highest);
          highest = std::max(highest, us[u]);
        }
      }
    }
    // Pixels that see nothing are not occluded (they are missing anyway).
    for (int u = 0; u < width; ++u) occluded[u] &= static_cast<uint8_t>(disparity[u] != 0.0f);
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
    const std::vector<PixelSpan> spans = MovingSpans(view);
    GeometrySink sink(*this, view, true);
    scene->Cast(k, view.world_T_view, spans, RayScene::Target::kMoving, view.current.depth.data(),
                &sink);
    auto t1 = Clock::now();
    timings.cast += Seconds(t0, t1);
    // Rows whose occlusion can differ from the cache: those touched now or last frame (others
    // keep the cached occlusion: their depth equals the cache).
    std::vector<int> rows;
    if (all_rows_dirty) {
      rows = all_rows;
    } else {
      std::vector<char> row_dirty(k.height, 0);
      for (const PixelSpan& s : view.dirty) row_dirty[s.row] = 1;
      for (const PixelSpan& s : spans) row_dirty[s.row] = 1;
      for (int v = 0; v < k.height; ++v) {
        if (row_dirty[v]) rows.push_back(v);
      }
    }
    Occlude(view, rows);
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
    const auto color_key = static_cast<uint32_t>(Mix64(frame_key ^ 0xD1B54A32D192ED03ULL));
    q.gauss = GaussTable().data();
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
    const int dw = dk.width;
    const int dh = dk.height;
    const int cw = ck.width;
    const int ch = ck.height;
    const int color_pairs = (3 * cw + 1) / 2;  // hashes per colour row
    const float* small_gauss = SmallGaussTable().data();

    // Depth and colour rows in one loop (one task wakes both cores once per frame).
    const int rows = std::max(dh, ch);
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, 16), [&](const tbb::blocked_range<int>& r) {
      std::vector<uint8_t> edge(dw);
      std::vector<uint32_t> hash(dw);
      std::vector<uint16_t> index(3 * static_cast<size_t>(cw) + 1);
      for (int v = r.begin(); v != r.end(); ++v) {
        if (v < dh) {
          uint16_t* out = &frame->depth[static_cast<size_t>(v) * dw];
          if (!q.noise) {
            ExactDepthRow(q, dv.current, v, dw, out);
          } else if (q.quantise) {
            NoisyDepthRow<true>(q, dv.current, v, dw, dh, edge.data(), hash.data(), out);
          } else {
            NoisyDepthRow<false>(q, dv.current, v, dw, dh, edge.data(), hash.data(), out);
          }
        }
        if (v < ch) {
          const size_t row = 3 * static_cast<size_t>(v) * cw;
          if (!q.noise) {
            std::copy_n(&cv.current.color[row], 3 * cw, &frame->rgb[row]);
          } else {
            ColorRow(&cv.current.color[row], color_key,
                     static_cast<uint32_t>(v) * static_cast<uint32_t>(color_pairs), 3 * cw,
                     color_sigma.data(), small_gauss, index.data(), &frame->rgb[row]);
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
