#include "sim/internal/avx2_kernels.h"

#include <limits>

#include "sim/internal/counter_random.h"

#if MMH_SENSOR_AVX2
#include <immintrin.h>
#endif

namespace mmh::sim::internal {

bool UseAvx2Default() {
#if MMH_SENSOR_AVX2
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}
std::atomic<bool>& UseAvx2() {
  static std::atomic<bool> use{UseAvx2Default()};
  return use;
}

#if MMH_SENSOR_AVX2
// GCC 12's intrinsics headers trip -Wmaybe-uninitialized on their own undefined-vector helpers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace {
MMH_AVX2 inline __m256i Set32(uint32_t x) { return _mm256_set1_epi32(static_cast<int>(x)); }
MMH_AVX2 inline __m256 Set(float x) { return _mm256_set1_ps(x); }
MMH_AVX2 inline __m256 Add(__m256 a, __m256 b) { return _mm256_add_ps(a, b); }
MMH_AVX2 inline __m256 Sub(__m256 a, __m256 b) { return _mm256_sub_ps(a, b); }
MMH_AVX2 inline __m256 Mul(__m256 a, __m256 b) { return _mm256_mul_ps(a, b); }
// a b + c rounded once, as std::fma in the portable kernels.
MMH_AVX2 inline __m256 Fma(__m256 a, __m256 b, __m256 c) { return _mm256_fmadd_ps(a, b, c); }
MMH_AVX2 inline __m256 Floor(__m256 x) {
  return _mm256_round_ps(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
}
// |a - b| (clearing the sign bit, as std::abs).
MMH_AVX2 inline __m256 AbsDiff(__m256 a, __m256 b) {
  return _mm256_andnot_ps(Set(-0.0f), Sub(a, b));
}
// mask ? b : a per lane (mask lanes all ones or all zeros).
MMH_AVX2 inline __m256 Select(__m256 mask, __m256 a, __m256 b) {
  return _mm256_blendv_ps(a, b, mask);
}

MMH_AVX2 inline __m256i Mix32x8(__m256i x) {
  x = _mm256_xor_si256(x, _mm256_srli_epi32(x, 16));
  x = _mm256_mullo_epi32(x, Set32(0x7feb352du));
  x = _mm256_xor_si256(x, _mm256_srli_epi32(x, 15));
  x = _mm256_mullo_epi32(x, Set32(0x846ca68bu));
  x = _mm256_xor_si256(x, _mm256_srli_epi32(x, 16));
  return x;
}
// (first + j) * 0x9E3779B9 mod 2^32 for lanes j = 0 .. 7, as first * 0x9E3779B9 + j * 0x9E3779B9
// (the same words as CounterHash's product).
MMH_AVX2 inline __m256i ScrambledCounters(uint32_t first) {
  constexpr uint32_t kGolden = 0x9E3779B9u;
  return _mm256_add_epi32(
      Set32(first * kGolden),
      _mm256_setr_epi32(0, static_cast<int>(kGolden), static_cast<int>(2 * kGolden),
                        static_cast<int>(3 * kGolden), static_cast<int>(4 * kGolden),
                        static_cast<int>(5 * kGolden), static_cast<int>(6 * kGolden),
                        static_cast<int>(7 * kGolden)));
}
// CounterHash of the counters behind ScrambledCounters(first).
MMH_AVX2 inline __m256i CounterHashx8(uint32_t key, __m256i scrambled) {
  return Mix32x8(_mm256_xor_si256(scrambled, Set32(key)));
}

// LnUnit, lane-parallel.
MMH_AVX2 inline __m256 LnUnitx8(__m256 u) {
  const __m256i bits = _mm256_castps_si256(u);
  __m256i e = _mm256_sub_epi32(_mm256_srli_epi32(bits, 23), Set32(127));
  __m256 m = _mm256_castsi256_ps(
      _mm256_or_si256(_mm256_and_si256(bits, Set32(0x007fffffu)), Set32(0x3f800000u)));
  const __m256 high = _mm256_cmp_ps(m, Set(kSqrt2), _CMP_GE_OQ);
  m = Select(high, m, Mul(m, Set(0.5f)));
  e = _mm256_sub_epi32(e, _mm256_castps_si256(high));  // high lanes are -1: e + 1
  const __m256 s = _mm256_div_ps(Sub(m, Set(1.0f)), Add(m, Set(1.0f)));
  const __m256 s2 = Mul(s, s);
  __m256 series = Fma(s2, Set(1.0f / 9), Set(1.0f / 7));
  series = Fma(s2, series, Set(1.0f / 5));
  series = Fma(s2, series, Set(1.0f / 3));
  series = Fma(s2, series, Set(1.0f));
  return Fma(_mm256_cvtepi32_ps(e), Set(kLn2), Mul(Mul(Set(2.0f), s), series));
}

// BoxMuller, lane-parallel.
MMH_AVX2 inline void BoxMullerx8(__m256i h, __m256* c, __m256* s) {
  const __m256 u1 =
      Mul(Add(_mm256_cvtepi32_ps(_mm256_srli_epi32(h, 16)), Set(0.5f)), Set(1.0f / 65536.0f));
  const __m256 r = _mm256_sqrt_ps(Mul(Set(-2.0f), LnUnitx8(u1)));
  const __m256i q = _mm256_and_si256(_mm256_srli_epi32(h, 14), Set32(3));
  const __m256 t = Mul(Add(_mm256_cvtepi32_ps(_mm256_and_si256(h, Set32(0x3fff))), Set(0.5f)),
                       Set(1.0f / 16384.0f));
  const __m256 x = Mul(Sub(t, Set(0.5f)), Set(kHalfPi));
  const __m256 x2 = Mul(x, x);
  __m256 sin_x = Fma(x2, Set(1.0f / 362880), Set(-1.0f / 5040));
  sin_x = Fma(x2, sin_x, Set(1.0f / 120));
  sin_x = Fma(x2, sin_x, Set(-1.0f / 6));
  sin_x = Fma(Mul(x, x2), sin_x, x);
  __m256 cos_x = Fma(x2, Set(-1.0f / 3628800), Set(1.0f / 40320));
  cos_x = Fma(x2, cos_x, Set(-1.0f / 720));
  cos_x = Fma(x2, cos_x, Set(1.0f / 24));
  cos_x = Fma(x2, cos_x, Set(-1.0f / 2));
  cos_x = Fma(x2, cos_x, Set(1.0f));
  const __m256 odd =
      _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(q, Set32(1)), Set32(1)));
  const __m256 a = Select(odd, cos_x, sin_x);
  const __m256 b = Select(odd, sin_x, cos_x);
  const __m256 negate_cos = _mm256_castsi256_ps(
      _mm256_or_si256(_mm256_cmpeq_epi32(q, Set32(1)), _mm256_cmpeq_epi32(q, Set32(2))));
  const __m256 negate_sin = _mm256_castsi256_ps(_mm256_cmpgt_epi32(q, Set32(1)));
  const __m256 sign = Set(-0.0f);
  const __m256 cos_angle = _mm256_xor_ps(a, _mm256_and_ps(negate_cos, sign));
  const __m256 sin_angle = _mm256_xor_ps(b, _mm256_and_ps(negate_sin, sign));
  *c = Mul(r, cos_angle);
  *s = Mul(r, sin_angle);
}

// Lanes (a0 b0 a1 b1 a2 b2 a3 b3) and (a4 b4 ... a7 b7) of two 8-lane vectors.
MMH_AVX2 inline void Interleave(__m256i a, __m256i b, __m256i* first, __m256i* second) {
  const __m256i low = _mm256_unpacklo_epi32(a, b);   // a0 b0 a1 b1 | a4 b4 a5 b5
  const __m256i high = _mm256_unpackhi_epi32(a, b);  // a2 b2 a3 b3 | a6 b6 a7 b7
  *first = _mm256_permute2x128_si256(low, high, 0x20);
  *second = _mm256_permute2x128_si256(low, high, 0x31);
}
}  // namespace

MMH_AVX2 void DepthNoiseAvx2(const DepthParams& q, uint32_t first_pixel, int n,
                             uint32_t* drop_bits, float* normal) {
  // An odd first pixel is the second of its pair: the portable code takes it.
  int i = static_cast<int>(first_pixel & 1u);
  if (i == 1 && n > 0) DepthNoisePortable(q, first_pixel, 1, drop_bits, normal);
  for (; i + 16 <= n; i += 16) {
    const uint32_t pair = (first_pixel + static_cast<uint32_t>(i)) >> 1;
    const __m256i counters = ScrambledCounters(pair);
    __m256 c, s;
    BoxMullerx8(CounterHashx8(q.key_c, counters), &c, &s);
    __m256i first, second;
    Interleave(_mm256_castps_si256(c), _mm256_castps_si256(s), &first, &second);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(normal + i), first);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(normal + i + 8), second);
    const __m256i h = CounterHashx8(q.key_b, counters);
    Interleave(_mm256_and_si256(h, Set32(0xffffu)), _mm256_srli_epi32(h, 16), &first, &second);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(drop_bits + i), first);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(drop_bits + i + 8), second);
  }
  if (i < n) {
    DepthNoisePortable(q, first_pixel + static_cast<uint32_t>(i), n - i, drop_bits + i,
                       normal + i);
  }
}

namespace {
// Pixels j .. j + 7 of DepthRowPortable (pointers at pixel j) given their disparities and their
// left and right neighbours': the samples as 32-bit integers, the edge flags as bits 0-7.
template <bool kQuantise>
MMH_AVX2 inline __m256i DepthLanesAvx2(const DepthParams& q, __m256 d, __m256 left, __m256 right,
                                       const float* up, const float* down, const float* depth,
                                       const float* cos_incidence, const uint8_t* occluded,
                                       const uint32_t* drop_bits, const float* normal,
                                       uint32_t* edge_flags) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 half = Set(0.5f);
  const __m256 jump =
      _mm256_max_ps(_mm256_max_ps(AbsDiff(d, left), AbsDiff(d, right)),
                    _mm256_max_ps(AbsDiff(d, _mm256_loadu_ps(up)), AbsDiff(d, _mm256_loadu_ps(down))));
  const __m256i occ =
      _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(occluded)));
  const __m256 keep =
      _mm256_and_ps(_mm256_cmp_ps(d, zero, _CMP_NEQ_UQ),
                    _mm256_castsi256_ps(_mm256_cmpeq_epi32(occ, _mm256_setzero_si256())));
  *edge_flags = static_cast<uint32_t>(
      _mm256_movemask_ps(_mm256_and_ps(keep, _mm256_cmp_ps(jump, Set(q.edge_jump), _CMP_GT_OQ))));
  const __m256 g = _mm256_loadu_ps(normal);
  // DepthSample, lane-parallel.
  __m256i step = _mm256_cvttps_epi32(
      Mul(_mm256_loadu_ps(cos_incidence), Set(static_cast<float>(kCosSteps))));
  step = _mm256_min_epi32(step, _mm256_set1_epi32(kCosSteps));
  const __m256 u_drop =
      Mul(_mm256_cvtepi32_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(drop_bits))),
          Set(1.0f / 65536.0f));
  const __m256 z = Select(keep, Set(1.0f), _mm256_loadu_ps(depth));
  const __m256 dz = Sub(z, Set(q.axial_z0));
  __m256 sigma = Fma(Mul(Set(q.axial_b), dz), dz, Set(q.axial_a));
  __m256 drop = Set(q.drop[kCosSteps]);
  // Steps from q.flat_step on have no grazing term (it is exactly 0, adding it changes nothing)
  // and the dropout probability of the last step: no gathers when all lanes are there.
  if (_mm256_movemask_epi8(_mm256_cmpgt_epi32(_mm256_set1_epi32(q.flat_step), step)) != 0) {
    sigma = Add(sigma, _mm256_div_ps(_mm256_i32gather_ps(q.grazing_sigma, step, 4),
                                     _mm256_sqrt_ps(z)));
    drop = _mm256_i32gather_ps(q.drop, step, 4);
  }
  const __m256 zn = Fma(sigma, g, z);
  __m256 zo = zn;
  __m256 valid = keep;
  if constexpr (kQuantise) {
    const __m256 lattice = Set(q.lattice), raw_offset = Set(q.raw_offset);
    const __m256 raw = Floor(Add(Sub(raw_offset, _mm256_div_ps(lattice, zn)), half));
    zo = _mm256_div_ps(lattice, Sub(raw_offset, raw));
    valid = _mm256_and_ps(valid, _mm256_and_ps(_mm256_cmp_ps(raw, zero, _CMP_GE_OQ),
                                               _mm256_cmp_ps(raw, Set(2046.0f), _CMP_LE_OQ)));
  }
  valid = _mm256_and_ps(valid, _mm256_cmp_ps(u_drop, drop, _CMP_GE_OQ));
  valid = _mm256_and_ps(valid, _mm256_and_ps(_mm256_cmp_ps(zo, Set(q.min_depth), _CMP_GE_OQ),
                                             _mm256_cmp_ps(zo, Set(q.max_depth), _CMP_LE_OQ)));
  __m256 units = Floor(Add(Mul(zo, Set(q.inverse_scale)), half));
  units = _mm256_min_ps(units, Set(65535.0f));  // (units < max) ? units : max, as scalar
  units = _mm256_and_ps(valid, units);           // +0 where not valid
  return _mm256_cvttps_epi32(units);
}

// Pixels i .. i + 15 of DepthRowPortable, with their edge flags as bits i .. i + 15 of edge_bits
// (ORed in); `last`: pixel i + 15 ends the row (its right neighbour counts as equal).
template <bool kQuantise>
MMH_AVX2 inline void DepthBlockAvx2(const DepthParams& q, const float* up, const float* row,
                                    const float* down, const float* depth,
                                    const float* cos_incidence, const uint8_t* occluded,
                                    const uint32_t* drop_bits, const float* normal, int i,
                                    bool last, uint64_t* edge_bits, uint16_t* out) {
  const __m256 d0 = _mm256_loadu_ps(row + i), d1 = _mm256_loadu_ps(row + i + 8);
  __m256 right1;
  if (last) {
    // Lanes 0-6 from row i + 9 .., lane 7 (pixel i + 15) its own disparity.
    const __m256i first7 = _mm256_setr_epi32(-1, -1, -1, -1, -1, -1, -1, 0);
    right1 = _mm256_blend_ps(_mm256_maskload_ps(row + i + 9, first7), d1, 0x80);
  } else {
    right1 = _mm256_loadu_ps(row + i + 9);
  }
  uint32_t flags0, flags1;
  const __m256i units0 = DepthLanesAvx2<kQuantise>(
      q, d0, _mm256_loadu_ps(row + i - 1), _mm256_loadu_ps(row + i + 1), up + i, down + i,
      depth + i, cos_incidence + i, occluded + i, drop_bits + i, normal + i, &flags0);
  const int j = i + 8;
  const __m256i units1 = DepthLanesAvx2<kQuantise>(
      q, d1, _mm256_loadu_ps(row + j - 1), right1, up + j, down + j, depth + j,
      cos_incidence + j, occluded + j, drop_bits + j, normal + j, &flags1);
  SetEdgeBits(edge_bits, i, flags0 | flags1 << 8);
  // Units in [0, 65535]: unsigned saturation keeps them; the pack works per 128-bit half.
  const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi32(units0, units1), 0xd8);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), packed);
}
}  // namespace

template <bool kQuantise>
MMH_AVX2 void DepthRowAvx2(const DepthParams& q, const float* up, const float* row,
                           const float* down, const float* depth, const float* cos_incidence,
                           const uint8_t* occluded, const uint32_t* drop_bits, const float* normal,
                           int n, uint8_t* edge, uint64_t* edge_bits, uint16_t* out) {
  if (n < 17) {
    DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                                0, n, edge, out);
    PackEdgeBits(edge, 0, n, edge_bits);
    return;
  }
  // Pixel 0 (no left neighbour): the portable code, on pixels 0 and 1 so that pixel 0 compares
  // with its right neighbour (pixel 1, taken there as the row's end, is the first block's).
  DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              0, 2, edge, out);
  PackEdgeBits(edge, 0, 1, edge_bits);
  int i = 1;
  for (; i + 16 < n; i += 16) {
    DepthBlockAvx2<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              i, false, edge_bits, out);
  }
  // The last 16 pixels (again where they overlap the previous block: same values).
  if (i < n) {
    DepthBlockAvx2<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              n - 16, true, edge_bits, out);
  }
}
template MMH_AVX2 void DepthRowAvx2<true>(const DepthParams&, const float*, const float*,
                                          const float*, const float*, const float*,
                                          const uint8_t*, const uint32_t*, const float*, int,
                                          uint8_t*, uint64_t*, uint16_t*);
template MMH_AVX2 void DepthRowAvx2<false>(const DepthParams&, const float*, const float*,
                                           const float*, const float*, const float*,
                                           const uint8_t*, const uint32_t*, const float*, int,
                                           uint8_t*, uint64_t*, uint16_t*);

namespace {
// Pixel k of ScoreSegmentAvx2 on its own (the last pixels of a segment), with the scalar
// operations of ScoreAndTakeBest and TakeSecond.
void ScorePixel(const int32_t* cross, const int32_t* sum_a, const double* inverse_a,
                const int32_t* sum_b, const double* inverse_b, double count, int lo, int hi,
                const int* first, const int* last, int k, int stride, double* scores,
                double* best, int* best_d, double* left, double* right, double* second) {
  double top = -std::numeric_limits<double>::infinity(), previous = 0.0;
  int top_d = -1;
  for (int d = lo; d <= hi; ++d) {
    const size_t at = static_cast<size_t>(d - lo) * stride + k;
    const int b = k - (d - lo);
    const double numerator = count * static_cast<double>(cross[at]) -
                             static_cast<double>(sum_a[k]) * static_cast<double>(sum_b[b]);
    const double x = numerator * inverse_a[k] * inverse_b[b];
    scores[at] = x;
    right[k] = d == top_d + 1 ? x : right[k];
    const bool better = (d >= first[k]) & (d <= last[k]) & (x > top);
    top = better ? x : top;
    top_d = better ? d : top_d;
    left[k] = better ? previous : left[k];
    previous = x;
  }
  double runner_up = -1.0;
  for (int d = lo; d <= hi; ++d) {
    const double x = scores[static_cast<size_t>(d - lo) * stride + k];
    const int distance = d - top_d;
    const bool take =
        (d >= first[k]) & (d <= last[k]) & ((distance >= 2) | (distance <= -2)) & (x > runner_up);
    runner_up = take ? x : runner_up;
  }
  best[k] = top;
  best_d[k] = top_d;
  second[k] = runner_up;
}
// Four 32-bit integers as doubles (exact).
MMH_AVX2 inline __m256d Load4(const int32_t* x) {
  return _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(x)));
}
}  // namespace

// Four pixels at a time in double lanes; disparities, search bounds and the best d as doubles
// (whole numbers, exact), so that every comparison is one vcmppd.
MMH_AVX2 void ScoreSegmentAvx2(const int32_t* cross, const int32_t* sum_a, const double* inverse_a,
                               const int32_t* sum_b, const double* inverse_b, double count, int lo,
                               int hi, const int* first, const int* last, int n, int stride,
                               double* scores, double* best, int* best_d, double* left,
                               double* right, double* second) {
  const __m256d count4 = _mm256_set1_pd(count), one = _mm256_set1_pd(1.0),
                two = _mm256_set1_pd(2.0), minus_two = _mm256_set1_pd(-2.0),
                minus_infinity = _mm256_set1_pd(-std::numeric_limits<double>::infinity());
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256d a = Load4(sum_a + k), inverse = _mm256_loadu_pd(inverse_a + k);
    const __m256d from = Load4(first + k), to = Load4(last + k);
    __m256d top = minus_infinity;
    __m256d top_d = _mm256_set1_pd(-1.0), previous = _mm256_setzero_pd();
    __m256d beside_left = _mm256_loadu_pd(left + k), beside_right = _mm256_loadu_pd(right + k);
    for (int d = lo; d <= hi; ++d) {
      const size_t at = static_cast<size_t>(d - lo) * stride + k;
      const int b = k - (d - lo);
      const __m256d numerator =
          _mm256_sub_pd(_mm256_mul_pd(count4, Load4(cross + at)), _mm256_mul_pd(a, Load4(sum_b + b)));
      const __m256d x =
          _mm256_mul_pd(_mm256_mul_pd(numerator, inverse), _mm256_loadu_pd(inverse_b + b));
      _mm256_storeu_pd(scores + at, x);
      const __m256d dd = _mm256_set1_pd(static_cast<double>(d));
      beside_right = _mm256_blendv_pd(beside_right, x,
                                      _mm256_cmp_pd(dd, _mm256_add_pd(top_d, one), _CMP_EQ_OQ));
      // better ? x : top as max(candidate, top), candidate = x inside the search and -inf
      // outside (vmaxpd(a, b) is a > b ? a : b): one operation on the chain from d to d + 1.
      const __m256d candidate = _mm256_blendv_pd(
          minus_infinity, x,
          _mm256_and_pd(_mm256_cmp_pd(dd, from, _CMP_GE_OQ), _mm256_cmp_pd(dd, to, _CMP_LE_OQ)));
      const __m256d better = _mm256_cmp_pd(candidate, top, _CMP_GT_OQ);
      top = _mm256_max_pd(candidate, top);
      top_d = _mm256_blendv_pd(top_d, dd, better);
      beside_left = _mm256_blendv_pd(beside_left, previous, better);
      previous = x;
    }
    __m256d runner_up = _mm256_set1_pd(-1.0);
    for (int d = lo; d <= hi; ++d) {
      const __m256d x = _mm256_loadu_pd(scores + static_cast<size_t>(d - lo) * stride + k);
      const __m256d dd = _mm256_set1_pd(static_cast<double>(d));
      const __m256d distance = _mm256_sub_pd(dd, top_d);
      const __m256d far = _mm256_or_pd(_mm256_cmp_pd(distance, two, _CMP_GE_OQ),
                                       _mm256_cmp_pd(distance, minus_two, _CMP_LE_OQ));
      const __m256d take = _mm256_and_pd(
          _mm256_and_pd(_mm256_cmp_pd(dd, from, _CMP_GE_OQ), _mm256_cmp_pd(dd, to, _CMP_LE_OQ)),
          _mm256_and_pd(far, _mm256_cmp_pd(x, runner_up, _CMP_GT_OQ)));
      runner_up = _mm256_blendv_pd(runner_up, x, take);
    }
    _mm256_storeu_pd(best + k, top);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(best_d + k), _mm256_cvttpd_epi32(top_d));
    _mm256_storeu_pd(left + k, beside_left);
    _mm256_storeu_pd(right + k, beside_right);
    _mm256_storeu_pd(second + k, runner_up);
  }
  for (; k < n; ++k) {
    ScorePixel(cross, sum_a, inverse_a, sum_b, inverse_b, count, lo, hi, first, last, k, stride,
               scores, best, best_d, left, right, second);
  }
}

// NoisyColor of 8 bytes at a time: slot j of value v stands for the byte v - 2^(slot_bits - 1) +
// j with probability threshold / 2^kColorThresholdBits, otherwise for its alias. The entries are
// gathered (Zen 3: about 4 cycles for 8; the AVX-512 kernel's permutes need 4 per 32-slot row
// here).
MMH_AVX2 void ColorRowAvx2(const ColorParams& p, const uint8_t* in, uint32_t first_counter, int n,
                           uint8_t* out) {
  const int bits = p.slot_bits;
  const __m256i slot_mask = _mm256_set1_epi32((1 << bits) - 1);
  const __m256i half = _mm256_set1_epi32(1 << (bits - 1));
  const __m128i slot_shift = _mm_cvtsi32_si128(bits);
  // The low byte of each 32-bit lane, into bytes 0-3 of each 128-bit half, then halves joined.
  const __m256i low_bytes = _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                                             -1, -1, 0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1,
                                             -1, -1, -1, -1);
  const __m256i join = _mm256_setr_epi32(0, 4, 1, 1, 1, 1, 1, 1);
  const auto* table = reinterpret_cast<const int*>(p.table);
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256i h =
        CounterHashx8(p.key, ScrambledCounters(first_counter + static_cast<uint32_t>(i)));
    const __m256i value =
        _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(in + i)));
    const __m256i slot = _mm256_and_si256(h, slot_mask);
    const __m256i entry =
        _mm256_i32gather_epi32(table, _mm256_or_si256(_mm256_sll_epi32(value, slot_shift), slot), 4);
    // (h >> 9) < (entry >> 8): both below 2^24, so the signed comparison is the unsigned one.
    const __m256i take_own = _mm256_cmpgt_epi32(_mm256_srli_epi32(entry, 8),
                                                _mm256_srli_epi32(h, 32 - kColorThresholdBits));
    const __m256i own = _mm256_sub_epi32(_mm256_add_epi32(value, slot), half);
    const __m256i chosen = _mm256_blendv_epi8(entry, own, take_own);
    const __m256i bytes =
        _mm256_permutevar8x32_epi32(_mm256_shuffle_epi8(chosen, low_bytes), join);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out + i), _mm256_castsi256_si128(bytes));
  }
  ColorRowPortable(p, in + i, first_counter + static_cast<uint32_t>(i), n - i, out + i);
}

#pragma GCC diagnostic pop
#endif  // MMH_SENSOR_AVX2

}  // namespace mmh::sim::internal
