// The per-pixel depth model of the synthetic Kinect (docs/sensor.md, "Depth", steps 3-7): axial
// noise, disparity lattice, range and dropouts, row by row, in portable C++ or the AVX-512 or AVX2
// kernels (avx512_kernels.h, avx2_kernels.h), which give the same bytes.
#pragma once

#include <cmath>
#include <cstdint>

namespace mmh::sim::internal {

// Tables indexed by the incidence cosine quantised to kCosSteps.
constexpr int kCosSteps = 1024;

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
void DepthNoisePortable(const DepthParams& q, uint32_t first_pixel, int n, uint32_t* drop_bits,
                        float* normal);
// DepthNoisePortable or its AVX-512 or AVX2 kernel where enabled (UseAvx512, UseAvx2): the same
// numbers.
void DepthNoise(const DepthParams& q, uint32_t first_pixel, int n, uint32_t* drop_bits,
                float* normal);

// A row of depth pixels [first, n): whether each is kept (something hit, not occluded) and an
// edge (largest 4-neighbour disparity difference above edge_jump; outside the image counts as
// equal), and its sample as if it were no edge.
template <bool kQuantise>
void DepthRowPortable(const DepthParams& q, const float* up, const float* row, const float* down,
                      const float* depth, const float* cos_incidence, const uint8_t* occluded,
                      const uint32_t* drop_bits, const float* normal, int first, int n,
                      uint8_t* edge, uint16_t* out);

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

// One depth row: its random numbers (drop_bits, normal: #n scratch), then the pixels, with the
// edge flags as bits (edge_bits: #ceil(n / 64); edge: #n scratch). The AVX-512 or AVX2 kernels
// where enabled (UseAvx512, UseAvx2), the portable ones otherwise.
template <bool kQuantise>
void DepthRow(const DepthParams& q, const float* up, const float* row, const float* down,
              const float* depth, const float* cos_incidence, const uint8_t* occluded,
              uint32_t first_pixel, int n, uint8_t* edge, uint64_t* edge_bits, uint32_t* drop_bits,
              float* normal, uint16_t* out);

// f b / z of a cast packet's 16 lanes (lanes without a hit compute values nobody reads).
void DisparityLanes(const float* __restrict depth, float scale, float* __restrict disparity);

}  // namespace mmh::sim::internal
