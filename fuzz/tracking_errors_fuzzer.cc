// libFuzzer target: the per-frame table of tracked takes (pipeline/tracking_frames.h; a full
// study's or run's tracking_errors.csv, read by `mmh error-model`). What reads is written back
// and must read the same and write the same bytes (its numbers are written in their shortest
// exact form).
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_input.h"
#include "pipeline/tracking_frames.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("tracking_errors.csv",
                                     {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const std::vector<pipeline::TakeFrames> read = pipeline::ReadTakeFramesCsv(path);
    const std::string text = pipeline::TakeFramesCsv(read);
    const auto again_path = fuzz::WriteInput("tracking_errors_again.csv", text);
    if (pipeline::TakeFramesCsv(pipeline::ReadTakeFramesCsv(again_path)) != text) {
      __builtin_trap();
    }
  });
  return 0;
}
