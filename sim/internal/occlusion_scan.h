// Occlusion of the projector and the IR camera by row scans (docs/sensor.md, "Depth" step 1 and
// "Occlusion windows"): the windowed scan of incremental frames, the static scene's cached scan,
// the scan values of a row.
#pragma once

#include <cstdint>
#include <limits>

namespace mmh::sim::internal {

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
                            uint8_t* flags);
// OcclusionWindowPortable or its vector kernel (same window, same flags).
template <bool kFromRight>
int OcclusionWindow(const float* us, const float* cached, int n, int first, int last,
                    uint8_t* flags);

// The flags and inclusive extrema of a whole row's scan for one source (the static scene's, for
// OcclusionWindowPortable): the same flags as the full scans.
void OcclusionCacheRow(const float* us, int n, bool from_right, float* extremum, uint8_t* flags);

// Occlusion scan values of one row for a light source at x = source:
// u_s = u - shift * disparity; pixels that see nothing get `none` (never an extremum).
void SourceColumns(const float* __restrict disparity, int n, float shift, float none,
                   float* __restrict us);

}  // namespace mmh::sim::internal
