#include "people/random.h"

#include <cmath>

namespace mmh::people {
namespace {

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace

std::uint64_t DeriveSeed(std::uint64_t seed, std::initializer_list<std::uint64_t> tags) {
  std::uint64_t h = SplitMix64(seed);
  for (const std::uint64_t tag : tags) h = SplitMix64(h ^ SplitMix64(tag + 0x632be59bd9b4e019ull));
  return h;
}

double Random::Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double Random::Normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = 2.0 * Uniform() - 1.0;
    v = 2.0 * Uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

int Random::Index(int n) {
  const std::uint64_t range = static_cast<std::uint64_t>(n);
  const std::uint64_t limit = UINT64_MAX - UINT64_MAX % range;
  std::uint64_t x;
  do {
    x = engine_();
  } while (x >= limit);
  return static_cast<int>(x % range);
}

double Random::Exponential(double mean) { return -mean * std::log1p(-Uniform()); }

}  // namespace mmh::people
