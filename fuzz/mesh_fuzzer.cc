// libFuzzer target: PLY and OBJ meshes (core/mesh_io.h: core/internal/ply_mesh_reader.h and
// obj_mesh_reader.h). The first byte chooses
// the format, the rest is the file.
#include <cstddef>
#include <cstdint>

#include "core/mesh_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  if (size == 0) return 0;
  const char* name = data[0] % 2 ? "model.obj" : "model.ply";
  const auto path = fuzz::WriteInput(name, {reinterpret_cast<const char*>(data) + 1, size - 1});
  fuzz::ExpectReadOrInputError([&] { LoadMesh(path); });
  return 0;
}
