#include "sim/internal/occlusion_scan.h"

#include <algorithm>

#include "core/simd.h"
#include "sim/internal/avx512_kernels.h"

namespace mmh::sim::internal {

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
template int OcclusionWindowPortable<true>(const float*, const float*, int, int, int, uint8_t*);
template int OcclusionWindowPortable<false>(const float*, const float*, int, int, int, uint8_t*);

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
template int OcclusionWindow<true>(const float*, const float*, int, int, int, uint8_t*);
template int OcclusionWindow<false>(const float*, const float*, int, int, int, uint8_t*);

// Occlusion scan values of one row for a light source at x = source (see the header):
// u_s = u - shift * disparity; pixels that see nothing get `none` (never an extremum).
MMH_SIMD_CLONES void SourceColumns(const float* __restrict disparity, int n, float shift,
                                   float none, float* __restrict us) {
  for (int i = 0; i < n; ++i) {
    const float d = disparity[i];
    us[i] = d != 0.0f ? static_cast<float>(i) - shift * d : none;
  }
}

}  // namespace mmh::sim::internal
