#include "sim/internal/depth_kernels.h"

#include <algorithm>

#include "core/simd.h"
#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "sim/internal/counter_random.h"
#include "sim/ray_scene.h"

namespace mmh::sim::internal {

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
template void DepthRowPortable<true>(const DepthParams&, const float*, const float*, const float*,
                                     const float*, const float*, const uint8_t*, const uint32_t*,
                                     const float*, int, int, uint8_t*, uint16_t*);
template void DepthRowPortable<false>(const DepthParams&, const float*, const float*,
                                      const float*, const float*, const float*, const uint8_t*,
                                      const uint32_t*, const float*, int, int, uint8_t*,
                                      uint16_t*);

void DepthNoise(const DepthParams& q, uint32_t first_pixel, int n, uint32_t* drop_bits,
                float* normal) {
#if MMH_SENSOR_AVX512
  if (UseAvx512().load(std::memory_order_relaxed)) {
    DepthNoiseAvx512(q, first_pixel, n, drop_bits, normal);
    return;
  }
#endif
#if MMH_SENSOR_AVX2
  if (UseAvx2().load(std::memory_order_relaxed)) {
    DepthNoiseAvx2(q, first_pixel, n, drop_bits, normal);
    return;
  }
#endif
  DepthNoisePortable(q, first_pixel, n, drop_bits, normal);
}

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
#if MMH_SENSOR_AVX2
  if (UseAvx2().load(std::memory_order_relaxed)) {
    DepthNoiseAvx2(q, first_pixel, n, drop_bits, normal);
    DepthRowAvx2<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal, n,
                            edge, edge_bits, out);
    return;
  }
#endif
  DepthNoisePortable(q, first_pixel, n, drop_bits, normal);
  DepthRowPortable<kQuantise>(q, up, row, down, depth, cos_incidence, occluded, drop_bits, normal,
                              0, n, edge, out);
  PackEdgeBits(edge, 0, n, edge_bits);
}
template void DepthRow<true>(const DepthParams&, const float*, const float*, const float*,
                             const float*, const float*, const uint8_t*, uint32_t, int, uint8_t*,
                             uint64_t*, uint32_t*, float*, uint16_t*);
template void DepthRow<false>(const DepthParams&, const float*, const float*, const float*,
                              const float*, const float*, const uint8_t*, uint32_t, int, uint8_t*,
                              uint64_t*, uint32_t*, float*, uint16_t*);

MMH_SIMD_CLONES void DisparityLanes(const float* __restrict depth, float scale,
                                    float* __restrict disparity) {
  for (int i = 0; i < HitPacket::kLanes; ++i) disparity[i] = scale / depth[i];
}

}  // namespace mmh::sim::internal
