// The Embree device config of every RayScene, in a file of its own so that run.json can name it
// without linking Embree (the light `mmh` executable loads no heavy library).
#pragma once

namespace mmh::sim {

// "isa=avx2" where the CPU has AVX2 and FMA, so that frames are the same bytes on every such
// machine (Embree's AVX-512 kernels return other hits in the last bits); null (Embree's own
// choice) elsewhere.
const char* EmbreeDeviceConfig();

}  // namespace mmh::sim
