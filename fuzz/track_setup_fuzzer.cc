// libFuzzer target: the tracker's setup calibration (track/setup.h: scene.json as mmh render
// writes it, or a hand-made one), read and validated.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "track/setup.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("scene.json", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const track::TrackSetup setup = track::ReadSetupJson(path);
    setup.Validate(path.string());
  });
  return 0;
}
