// Hand-vectorised AVX-512 kernels of the synthetic Kinect (GCC 12 vectorises neither the bit
// manipulation nor floor well). They mirror the portable kernels (depth_kernels.h,
// color_noise.h, occlusion_scan.h) operation by operation, so frames do not depend on which of
// them runs (tested with KinectSensor::SetVectorKernels(false)).
#pragma once

#include <atomic>
#include <cstdint>

#include "sim/internal/color_noise.h"
#include "sim/internal/depth_kernels.h"

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MMH_SENSOR_AVX512 1
#define MMH_AVX512 __attribute__((target("avx512f,avx512bw,avx512dq,avx512vl")))
#else
#define MMH_SENSOR_AVX512 0
#endif

namespace mmh::sim::internal {

// Whether the CPU has AVX-512 F, BW, DQ and VL.
bool UseAvx512Default();
// Whether the vector kernels run (KinectSensor::SetVectorKernels), for every sensor of the process.
std::atomic<bool>& UseAvx512();

#if MMH_SENSOR_AVX512
// DepthNoisePortable, 16 pairs (32 pixels) at a time.
MMH_AVX512 void DepthNoiseAvx512(const DepthParams& q, uint32_t first_pixel, int n,
                                 uint32_t* drop_bits, float* normal);
// DepthRowPortable over a whole row; edge: #n scratch for the portable code; edge_bits: zeroed.
template <bool kQuantise>
MMH_AVX512 void DepthRowAvx512(const DepthParams& q, const float* up, const float* row,
                               const float* down, const float* depth, const float* cos_incidence,
                               const uint8_t* occluded, const uint32_t* drop_bits,
                               const float* normal, int n, uint8_t* edge, uint64_t* edge_bits,
                               uint16_t* out);
// ColorRowPortable; kSlots: the alias table's slots (32 or 64: permutes; 0: gathers only).
template <int kSlots>
MMH_AVX512 void ColorRowAvx512(const ColorParams& p, const uint8_t* in, uint32_t first_counter,
                               int n, uint8_t* out);
// One direction of a full occlusion scan, ORed into `occluded` (n: a multiple of 16).
template <bool kFromRight>
MMH_AVX512 void OcclusionScanAvx512(const float* us, int n, uint8_t* occluded);
// OcclusionWindowPortable, 16 pixels at a time.
template <bool kFromRight>
MMH_AVX512 int OcclusionWindowAvx512(const float* us, const float* cached, int n, int first,
                                     int last, uint8_t* flags);
#endif

}  // namespace mmh::sim::internal
