// Colour noise of the synthetic Kinect (docs/sensor.md, "Colour"): each noisy byte drawn exactly
// from its rounded, clamped normal by Walker's alias method.
#pragma once

#include <cstdint>
#include <vector>

#include "sim/kinect_sensor.h"

namespace mmh::sim::internal {

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
std::vector<uint32_t> ColorAliasTable(const ColorModel& color, int* slot_bits);

// Colour noise on n bytes (RGB interleaved) of a row: byte i takes the hash of counter
// first_counter + i.
void ColorRowPortable(const ColorParams& p, const uint8_t* in, uint32_t first_counter, int n,
                      uint8_t* out);
// ColorRowPortable or its AVX-512 or AVX2 kernel where enabled (same bytes).
void ColorRow(const ColorParams& p, const uint8_t* in, uint32_t first_counter, int n,
              uint8_t* out);

}  // namespace mmh::sim::internal
