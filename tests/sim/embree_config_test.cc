// Tests of sim/embree_config.h: the Embree kernels every RayScene runs.
#include "sim/embree_config.h"

#include <gtest/gtest.h>

#include <string>

#include "sim/library_versions.h"

namespace mmh::sim {
namespace {

bool CpuHasAvx2AndFma() {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
  return false;
#endif
}

TEST(EmbreeConfigTest, EmbreeRunsItsAvx2KernelsWhereTheCpuHasThem) {
  if (!CpuHasAvx2AndFma()) {
    EXPECT_EQ(EmbreeDeviceConfig(), nullptr);
    GTEST_SKIP() << "no AVX2 and FMA: Embree picks its kernels";
  }
  ASSERT_NE(EmbreeDeviceConfig(), nullptr);
  EXPECT_EQ(std::string(EmbreeDeviceConfig()), "isa=avx2");
  // run.json's libraries name it.
  EXPECT_EQ(LibraryVersions()["embree_device"], "isa=avx2");
}

}  // namespace
}  // namespace mmh::sim
