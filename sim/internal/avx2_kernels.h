// Hand-vectorised AVX2 (+FMA) kernels of the synthetic Kinect for machines without AVX-512 (AMD
// Zen 1-3, Intel before Ice Lake): the depth noise (Box-Muller), the depth row and the colour
// noise, 8 lanes at a time. GCC 12 vectorises neither the portable noise loop (two normals per
// counter) nor the colour loop (it keeps the table lookup scalar behind a branch), and the
// portable kernels are about 10 times slower on such machines. They mirror the portable kernels
// (depth_kernels.h, color_noise.h) operation by operation, like the AVX-512 ones
// (avx512_kernels.h), so frames do not depend on which of them runs (tested).
#pragma once

#include <atomic>
#include <cstdint>

#include "sim/internal/avx512_kernels.h"
#include "sim/internal/color_noise.h"
#include "sim/internal/depth_kernels.h"

#if MMH_SENSOR_AVX512
#define MMH_SENSOR_AVX2 1
#define MMH_AVX2 __attribute__((target("avx2,fma")))
#else
#define MMH_SENSOR_AVX2 0
#endif

namespace mmh::sim::internal {

// Whether the CPU has AVX2 and FMA.
bool UseAvx2Default();
// Whether the AVX2 kernels run where the AVX-512 ones do not (KinectSensor::SetVectorKernels),
// for every sensor of the process.
std::atomic<bool>& UseAvx2();

#if MMH_SENSOR_AVX2
// DepthNoisePortable, 8 pairs (16 pixels) at a time.
MMH_AVX2 void DepthNoiseAvx2(const DepthParams& q, uint32_t first_pixel, int n,
                             uint32_t* drop_bits, float* normal);
// DepthRowPortable over a whole row; edge: #n scratch for the portable code; edge_bits: zeroed.
template <bool kQuantise>
MMH_AVX2 void DepthRowAvx2(const DepthParams& q, const float* up, const float* row,
                           const float* down, const float* depth, const float* cos_incidence,
                           const uint8_t* occluded, const uint32_t* drop_bits, const float* normal,
                           int n, uint8_t* edge, uint64_t* edge_bits, uint16_t* out);
// The structured-light matcher's scoring of one row of a segment (speckle_matcher.cc,
// ScoreAndTakeBest then TakeSecond for each d in [lo, hi]), with each pixel's best score, its
// neighbours and the second best kept in registers over all disparities: cross and scores at
// (d - lo) stride + k (k < n <= stride), sum_b and inverse_b of pixel k at d at [k - (d - lo)];
// best, best_d, second are set, left and right keep their values where no score is better.
MMH_AVX2 void ScoreSegmentAvx2(const int32_t* cross, const int32_t* sum_a, const double* inverse_a,
                               const int32_t* sum_b, const double* inverse_b, double count, int lo,
                               int hi, const int* first, const int* last, int n, int stride,
                               double* scores, double* best, int* best_d, double* left,
                               double* right, double* second);
// ColorRowPortable, the table entries gathered 8 at a time.
MMH_AVX2 void ColorRowAvx2(const ColorParams& p, const uint8_t* in, uint32_t first_counter, int n,
                           uint8_t* out);
#endif

}  // namespace mmh::sim::internal
