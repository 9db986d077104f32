// libFuzzer target: regression baselines (pipeline/baseline_file.h: baseline.json of `mmh
// regress`), read and checked.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "pipeline/baseline_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path =
      fuzz::WriteInput("baseline/baseline.json", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] { pipeline::ReadBaseline(path.parent_path()); });
  return 0;
}
