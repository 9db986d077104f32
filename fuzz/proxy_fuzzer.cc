// libFuzzer target: proxy files (sim/duplo.h, configs/proxies/*.json: DUPLO assemblies), read,
// built into their mesh (which validates the assembly again) and written back to JSON, which
// must read back to the same assembly.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "sim/duplo.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("proxy.json", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const sim::DuploAssembly assembly = sim::LoadDuploAssembly(path);
    const TriangleMesh mesh = sim::BuildDuploMesh(assembly, 4);
    if (mesh.faces.rows() == 0) __builtin_trap();
    const sim::DuploAssembly again =
        sim::ParseDuploAssembly(sim::DuploAssemblyToJson(assembly), "written");
    if (again.bricks.size() != assembly.bricks.size()) __builtin_trap();
  });
  return 0;
}
