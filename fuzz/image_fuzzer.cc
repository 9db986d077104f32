// libFuzzer target: depth and colour images (core/image_io.h): 16-bit depth PNG, colour images in
// any format, NYU raw disparity PGM, SUN RGB-D depth. The first byte chooses the reader.
#include <cstddef>
#include <cstdint>

#include "core/image_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  if (size == 0) return 0;
  const std::string_view bytes{reinterpret_cast<const char*>(data) + 1, size - 1};
  fuzz::ExpectReadOrInputError([&] {
    switch (data[0] % 4) {
      case 0:
        ReadDepthPng16(fuzz::WriteInput("depth.png", bytes));
        break;
      case 1:
        ReadRgbImage(fuzz::WriteInput("rgb.png", bytes));
        break;
      case 2:
        ReadNyuRawDisparity(fuzz::WriteInput("depth.pgm", bytes));
        break;
      default:
        ReadSunDepth(fuzz::WriteInput("sun.png", bytes));
        break;
    }
  });
  return 0;
}
