// libFuzzer target: TUM trajectories (core/tum_io.h), then the checks every algorithm assumes and
// a write that must read back to the same poses.
#include <cstddef>
#include <cstdint>

#include "core/trajectory.h"
#include "core/tum_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("take.tum", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const Trajectory take = ReadTum(path);
    ValidateTrajectory(take, path.string());
    WriteTum(fuzz::ScratchDir() / "written.tum", take);
    const Trajectory again = ReadTum(fuzz::ScratchDir() / "written.tum");
    if (again.size() != take.size() || again.timestamps != take.timestamps) __builtin_trap();
  });
  return 0;
}
