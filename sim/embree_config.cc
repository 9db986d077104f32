#include "sim/embree_config.h"

namespace mmh::sim {

const char* EmbreeDeviceConfig() {
  // Embree runs the widest kernels the CPU has, and its AVX-512 ones (16-wide BVH nodes and leaves)
  // return hits that differ from its AVX2 ones in the last bits: every frame, and the tracking and
  // montage after it, would depend on the machine that rendered it (the committed regression
  // baselines, made on an AVX2 machine, differed in 6 of the short one's 60 metrics on an AVX-512
  // one, and in none with this). Every CPU with AVX2 and FMA therefore runs the AVX2 kernels;
  // on AVX-512 machines that costs about 1.7 times the cast (bench/README.md).
#if defined(__x86_64__) || defined(__i386__)
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "isa=avx2";
#endif
  return nullptr;  // what Embree picks: frames may differ from AVX2 machines' in the last bits
}

}  // namespace mmh::sim
