#include "sim/internal/color_noise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/simd.h"
#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "sim/internal/counter_random.h"

namespace mmh::sim::internal {

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
#if MMH_SENSOR_AVX2
  if (UseAvx2().load(std::memory_order_relaxed)) {
    ColorRowAvx2(p, in, first_counter, n, out);
    return;
  }
#endif
  ColorRowPortable(p, in, first_counter, n, out);
}

}  // namespace mmh::sim::internal
