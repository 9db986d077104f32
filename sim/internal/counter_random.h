// Counter-based random numbers of the synthetic Kinect (docs/sensor.md, "Randomness"): 64- and
// 32-bit bijective mixes keyed by (seed, frame, stream) and applied to a pixel's counter, so that
// every pixel's noise is independent of the order and thread in which pixels are processed, and
// Box-Muller normals evaluated with IEEE operations only (every SIMD level rounds alike).
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace mmh::sim::internal {

// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix; keyed by (seed,
// frame, pixel) it is a counter-based generator, so every pixel's noise is independent of the
// order in which pixels are processed.
inline uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
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

}  // namespace mmh::sim::internal
