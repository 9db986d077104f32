#include "sim/internal/avx512_kernels.h"

#include <algorithm>
#include <limits>

#include "sim/internal/counter_random.h"
#include "sim/internal/occlusion_scan.h"

#if MMH_SENSOR_AVX512
#include <immintrin.h>
#endif

namespace mmh::sim::internal {

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

#if MMH_SENSOR_AVX512
// GCC 12's intrinsics headers trip -Wmaybe-uninitialized on their own undefined-vector helpers.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace {
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

}  // namespace

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
  // Pixel 0 (no left neighbour): the portable code, on pixels 0 and 1 so that pixel 0 compares
  // with its right neighbour (pixel 1, taken there as the row's end, is the first block's).
  // (Until 2026-11-28 on pixel 0 alone, as the row's end: its edge flag could differ from the
  // portable kernel's, found by tests/sim/sensor_kernels_test.cc.)
  DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              0, 2, edge, out);
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

template MMH_AVX512 void DepthRowAvx512<true>(const DepthParams&, const float*, const float*,
                                              const float*, const float*, const float*,
                                              const uint8_t*, const uint32_t*, const float*, int,
                                              uint8_t*, uint64_t*, uint16_t*);
template MMH_AVX512 void DepthRowAvx512<false>(const DepthParams&, const float*, const float*,
                                               const float*, const float*, const float*,
                                               const uint8_t*, const uint32_t*, const float*, int,
                                               uint8_t*, uint64_t*, uint16_t*);
template MMH_AVX512 void ColorRowAvx512<0>(const ColorParams&, const uint8_t*, uint32_t, int,
                                           uint8_t*);
template MMH_AVX512 void ColorRowAvx512<32>(const ColorParams&, const uint8_t*, uint32_t, int,
                                            uint8_t*);
template MMH_AVX512 void ColorRowAvx512<64>(const ColorParams&, const uint8_t*, uint32_t, int,
                                            uint8_t*);
template MMH_AVX512 void OcclusionScanAvx512<true>(const float*, int, uint8_t*);
template MMH_AVX512 void OcclusionScanAvx512<false>(const float*, int, uint8_t*);
template MMH_AVX512 int OcclusionWindowAvx512<true>(const float*, const float*, int, int, int,
                                                    uint8_t*);
template MMH_AVX512 int OcclusionWindowAvx512<false>(const float*, const float*, int, int, int,
                                                     uint8_t*);
#pragma GCC diagnostic pop
#endif  // MMH_SENSOR_AVX512

}  // namespace mmh::sim::internal
