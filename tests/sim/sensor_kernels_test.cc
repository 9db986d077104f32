// The synthetic Kinect's vector kernels (sim/internal/avx2_kernels.h, avx512_kernels.h) against
// the portable ones, bit for bit, on random rows: every start parity and row length around the
// vector widths, depth edges, misses, occluded pixels, grazing and flat cos steps, depths outside
// the range and off the lattice. Kernels the CPU lacks are skipped.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

#include "sim/internal/avx2_kernels.h"
#include "sim/internal/avx512_kernels.h"
#include "sim/internal/color_noise.h"
#include "sim/internal/counter_random.h"
#include "sim/internal/depth_kernels.h"

namespace mmh::sim::internal {
namespace {

using NoiseKernel = void (*)(const DepthParams&, uint32_t, int, uint32_t*, float*);
using RowKernel = void (*)(const DepthParams&, const float*, const float*, const float*,
                           const float*, const float*, const uint8_t*, const uint32_t*,
                           const float*, int, uint8_t*, uint64_t*, uint16_t*);
using ColorKernel = void (*)(const ColorParams&, const uint8_t*, uint32_t, int, uint8_t*);

struct Kernels {
  const char* name;
  NoiseKernel noise;
  RowKernel row_quantised, row_exact;
  ColorKernel color;
};

// The vector kernels this CPU runs (empty on one with neither).
std::vector<Kernels> VectorKernels() {
  std::vector<Kernels> kernels;
#if MMH_SENSOR_AVX2
  if (UseAvx2Default()) {
    kernels.push_back({"AVX2", DepthNoiseAvx2, DepthRowAvx2<true>, DepthRowAvx2<false>,
                       ColorRowAvx2});
  }
#endif
#if MMH_SENSOR_AVX512
  if (UseAvx512Default()) {
    kernels.push_back({"AVX-512", DepthNoiseAvx512, DepthRowAvx512<true>, DepthRowAvx512<false>,
                       [](const ColorParams& p, const uint8_t* in, uint32_t first, int n,
                          uint8_t* out) {
                         if (p.slot_bits <= 5) {
                           ColorRowAvx512<32>(p, in, first, n, out);
                         } else if (p.slot_bits == 6) {
                           ColorRowAvx512<64>(p, in, first, n, out);
                         } else {
                           ColorRowAvx512<0>(p, in, first, n, out);
                         }
                       }});
  }
#endif
  return kernels;
}

// A uniform in [0, 1) from the counter-based generator.
float Uniform(uint32_t key, uint32_t i) {
  return static_cast<float>(CounterHash(key, i) >> 8) * (1.0f / 16777216.0f);
}

// The per-cos-step tables of DepthParams: a grazing term and a higher dropout below flat_step,
// constant from there on (as KinectSensor builds them).
struct Tables {
  std::vector<float> lateral_cross, drop, grazing_sigma;
  explicit Tables(int flat_step)
      : lateral_cross(kCosSteps + 1), drop(kCosSteps + 1), grazing_sigma(kCosSteps + 1) {
    for (int s = 0; s <= kCosSteps; ++s) {
      const float graze = s < flat_step ? static_cast<float>(flat_step - s) / flat_step : 0.0f;
      lateral_cross[s] = 0.1f * graze;
      grazing_sigma[s] = 0.02f * graze;
      drop[s] = 0.01f + 0.9f * graze;
    }
  }
};

DepthParams Params(const Tables& t, int flat_step) {
  DepthParams q;
  q.key_a = 0x1234567u;
  q.key_b = 0x89abcdefu;
  q.key_c = 0x2468ace1u;
  q.lattice = 8.0f * 580.0f * 0.075f;
  q.raw_offset = 1092.5f;
  q.edge_jump = 1.5f;
  q.min_depth = 0.4f;
  q.max_depth = 4.0f;
  q.inverse_scale = 5000.0f;
  q.axial_a = 0.0012f;
  q.axial_b = 0.0019f;
  q.axial_z0 = 0.4f;
  q.lateral_cross = t.lateral_cross.data();
  q.drop = t.drop.data();
  q.grazing_sigma = t.grazing_sigma.data();
  q.flat_step = flat_step;
  return q;
}

TEST(DepthKernels, VectorNoiseEqualsThePortableNoise) {
  const std::vector<Kernels> kernels = VectorKernels();
  if (kernels.empty()) GTEST_SKIP() << "no vector kernels on this CPU";
  const Tables tables(kCosSteps);
  const DepthParams q = Params(tables, kCosSteps);
  for (const Kernels& k : kernels) {
    for (const uint32_t first : {0u, 1u, 640u * 17u, 640u * 17u + 1u, 4294967200u}) {
      for (const int n : {0, 1, 2, 15, 16, 17, 31, 32, 33, 47, 333, 640}) {
        std::vector<uint32_t> bits_a(n + 1, 7u), bits_b(n + 1, 7u);
        std::vector<float> normal_a(n + 1, 7.0f), normal_b(n + 1, 7.0f);
        DepthNoisePortable(q, first, n, bits_a.data(), normal_a.data());
        k.noise(q, first, n, bits_b.data(), normal_b.data());
        ASSERT_EQ(bits_a, bits_b) << k.name << " first " << first << " n " << n;
        ASSERT_EQ(0, std::memcmp(normal_a.data(), normal_b.data(), normal_a.size() * sizeof(float)))
            << k.name << " first " << first << " n " << n;
      }
    }
  }
}

// Every kernel set with and without quantisation.
std::vector<std::pair<Kernels, bool>> Cases(const std::vector<Kernels>& kernels) {
  std::vector<std::pair<Kernels, bool>> cases;
  for (const Kernels& k : kernels) {
    for (const bool quantise : {true, false}) cases.emplace_back(k, quantise);
  }
  return cases;
}

TEST(DepthKernels, VectorRowEqualsThePortableRow) {
  const std::vector<Kernels> kernels = VectorKernels();
  if (kernels.empty()) GTEST_SKIP() << "no vector kernels on this CPU";
  long missing = 0, edges = 0, pixels = 0;
  for (const int flat_step : {kCosSteps, 700}) {
    const Tables tables(flat_step);
    const DepthParams q = Params(tables, flat_step);
    for (const int n : {1, 9, 16, 17, 18, 24, 33, 40, 49, 333, 640}) {
      // Rows of random disparities with runs (surfaces), jumps (edges), zeros (misses); depths
      // from 0.2 to 5 m (outside the range at both ends), cos from 0 to 1.
      uint32_t c = static_cast<uint32_t>(n) * 1000u + static_cast<uint32_t>(flat_step);
      std::vector<float> up(n), row(n), down(n), depth(n), cos_incidence(n), normal(n);
      std::vector<uint8_t> occluded(n);
      std::vector<uint32_t> drop_bits(n);
      for (int u = 0; u < n; ++u) {
        const float z = 0.2f + 4.8f * Uniform(1, c++);
        depth[u] = z;
        row[u] = Uniform(2, c++) < 0.1f ? 0.0f : 43.5f / z;
        up[u] = Uniform(3, c++) < 0.5f ? row[u] : row[u] + 4.0f * (Uniform(4, c++) - 0.5f);
        down[u] = Uniform(5, c++) < 0.1f ? 0.0f : row[u] + 0.5f * Uniform(6, c++);
        cos_incidence[u] = Uniform(7, c++) < 0.3f ? 1.0f : Uniform(8, c++);
        occluded[u] = Uniform(9, c++) < 0.1f;
        drop_bits[u] = CounterHash(10, c++) & 0xffffu;
        normal[u] = 6.0f * (Uniform(11, c++) - 0.5f);
      }
      for (const auto& [k, quantise] : Cases(kernels)) {
        std::vector<uint8_t> edge(n);
        const int words = (n + 63) / 64;
        std::vector<uint64_t> bits_a(words + 1, 0), bits_b(words + 1, 0);
        std::vector<uint16_t> out_a(n, 1), out_b(n, 2);
        (quantise ? DepthRowPortable<true> : DepthRowPortable<false>)(
            q, up.data(), row.data(), down.data(), depth.data(), cos_incidence.data(),
            occluded.data(), drop_bits.data(), normal.data(), 0, n, edge.data(), out_a.data());
        PackEdgeBits(edge.data(), 0, n, bits_a.data());
        (quantise ? k.row_quantised : k.row_exact)(
            q, up.data(), row.data(), down.data(), depth.data(), cos_incidence.data(),
            occluded.data(), drop_bits.data(), normal.data(), n, edge.data(), bits_b.data(),
            out_b.data());
        ASSERT_EQ(out_a, out_b) << k.name << " n " << n << " quantise " << quantise;
        ASSERT_EQ(bits_a, bits_b) << k.name << " n " << n << " quantise " << quantise;
        missing += std::count(out_a.begin(), out_a.end(), 0);
        for (const uint64_t word : bits_a) edges += std::popcount(word);
        pixels += n;
      }
    }
  }
  // Missing and kept pixels and edges are all common.
  EXPECT_GT(missing, pixels / 10);
  EXPECT_LT(missing, pixels * 9 / 10);
  EXPECT_GT(edges, pixels / 10);
}

TEST(ColorNoiseKernels, VectorRowEqualsThePortableRow) {
  const std::vector<Kernels> kernels = VectorKernels();
  if (kernels.empty()) GTEST_SKIP() << "no vector kernels on this CPU";
  // Read noise 1.5, 2.5, 12: tables of 32, 64 and 512 slots per value.
  for (const double read_noise : {1.5, 2.5, 12.0}) {
    ColorModel model;
    model.read_noise = read_noise;
    ColorParams p;
    const std::vector<uint32_t> table = ColorAliasTable(model, &p.slot_bits);
    p.table = table.data();
    p.key = 0x5bd1e995u;
    for (const int n : {0, 1, 7, 8, 9, 16, 47, 48, 51, 100, 1920}) {
      // Runs of one colour (RGB repeating with period 3), random bytes, and the extremes.
      std::vector<uint8_t> in(n);
      for (int i = 0; i < n; ++i) {
        const int pixel = i / 3;
        in[i] = pixel % 7 < 4 ? static_cast<uint8_t>(40 * (i % 3) + 60)
                              : static_cast<uint8_t>(CounterHash(12, i) & 0xff);
        if (pixel % 11 == 5) in[i] = i % 2 ? 0 : 255;
      }
      for (const Kernels& k : kernels) {
        for (const uint32_t first : {0u, 3u * 640u * 5u + 7u}) {
          std::vector<uint8_t> out_a(n, 1), out_b(n, 2);
          ColorRowPortable(p, in.data(), first, n, out_a.data());
          k.color(p, in.data(), first, n, out_b.data());
          ASSERT_EQ(out_a, out_b) << k.name << " read noise " << read_noise << " n " << n;
        }
      }
    }
  }
}

}  // namespace
}  // namespace mmh::sim::internal
