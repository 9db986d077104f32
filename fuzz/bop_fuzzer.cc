// libFuzzer target: BOP scene folders (track/recording.h): the input is split at "\n----\n" into
// scene_camera.json, scene_gt.json and scene_gt_info.json (absent when its part is empty) of a
// folder whose images 000000..000002 (depth/ and rgb/) are small valid PNGs, made once, so the
// reader gets as far as reading frames and every object's ground truth.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz/fuzz_input.h"
#include "track/recording.h"

namespace {

const std::filesystem::path& Scene() {
  static const std::filesystem::path scene = [] {
    const std::filesystem::path f = mmh::fuzz::ScratchDir() / "bop_scene";
    mmh::fuzz::WriteTinyFrames(f, {"000000", "000001", "000002"});
    return f;
  }();
  return scene;
}

}  // namespace

// Once, before the first input: the frames are made (and the image readers started) here.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  Scene();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const std::filesystem::path& scene = Scene();
  fuzz::WriteParts({reinterpret_cast<const char*>(data), size}, "bop_scene",
                   {"scene_camera.json", "scene_gt.json", "scene_gt_info.json"});
  fuzz::ExpectReadOrInputError([&] {
    track::RecordingFrameSource source(scene);
    RgbdFrame frame;
    for (int i = 0; i < 4 && source.Next(&frame); ++i) {
    }
    for (const int id : source.object_ids()) source.Truth(id);
  });
  return 0;
}
