// libFuzzer target: YCB-Video's -meta.mat (track/mat_file.h: level-5 MAT-files, zlib-compressed
// elements) and its plain-text export, each read from the same input; every array read must
// fill its dimensions.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "track/mat_file.h"

namespace {

void CheckArrays(const mmh::track::MatFile& file) {
  for (const auto& [name, array] : file.arrays) {
    std::int64_t count = 1;
    for (const std::int64_t d : array.dims) {
      if (d < 0) __builtin_trap();
      count *= d;
    }
    if (count != array.size()) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const std::string_view bytes{reinterpret_cast<const char*>(data), size};
  const auto mat = fuzz::WriteInput("meta.mat", bytes);
  fuzz::ExpectReadOrInputError([&] { CheckArrays(track::ReadMatFile(mat)); });
  const auto text = fuzz::WriteInput("meta.txt", bytes);
  fuzz::ExpectReadOrInputError([&] { CheckArrays(track::ReadMatText(text)); });
  return 0;
}
