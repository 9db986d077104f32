// Clones of hot loops for AVX-512 and AVX2 machines, chosen at load time; the baseline build stays
// portable. -ffp-contract=off (CMakeLists.txt) keeps every clone's rounding identical, so results
// do not depend on the machine's vector width. Use only on functions with IEEE arithmetic and
// integer operations (no libm calls, whose vector variants may round differently).
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define MMH_SIMD_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define MMH_SIMD_CLONES
#endif
