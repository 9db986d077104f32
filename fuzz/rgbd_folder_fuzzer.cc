// libFuzzer target: RGB-D folder indexes and camera.json (core/rgbd_folder.h): the input is split
// at "\n----\n" into rgb.txt, depth.txt, groundtruth.txt and camera.json of a folder whose listed
// images are small valid PNGs (made once), so the reader gets as far as pairing and reading
// frames.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "core/rgbd_folder.h"
#include "fuzz/fuzz_input.h"

namespace {

const std::filesystem::path& Folder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path f = mmh::fuzz::ScratchDir() / "seq";
    mmh::fuzz::WriteTinyFrames(f, {"0.000000", "0.033333", "1"});
    return f;
  }();
  return folder;
}

}  // namespace

// Once, before the first input: the frames are made (and the image readers started) here.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  Folder();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const std::filesystem::path& folder = Folder();
  fuzz::WriteParts({reinterpret_cast<const char*>(data), size}, "seq",
                   {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.json"});
  fuzz::ExpectReadOrInputError([&] {
    RgbdFolderReader reader(folder);
    for (int i = 0; i < reader.size() && i < 4; ++i) {
      fuzz::ExpectReadOrInputError([&] { reader.Read(i); });
    }
    reader.ReadGroundtruth();
  });
  return 0;
}
