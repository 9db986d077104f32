// libFuzzer target: RGB-D folder indexes and camera.json (core/rgbd_folder.h): the input is split
// at "\n----\n" into rgb.txt, depth.txt, groundtruth.txt and camera.json of a folder whose listed
// images are small valid PNGs (made once), so the reader gets as far as pairing and reading
// frames.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "core/image_io.h"
#include "core/rgbd_folder.h"
#include "fuzz/fuzz_input.h"

namespace {

const std::filesystem::path& Folder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path f = mmh::fuzz::ScratchDir() / "seq";
    std::filesystem::create_directories(f / "rgb");
    std::filesystem::create_directories(f / "depth");
    mmh::DepthImage depth;
    depth.width = 4, depth.height = 3;
    depth.values.assign(12, 5000);
    mmh::RgbImage rgb;
    rgb.width = 4, rgb.height = 3;
    rgb.rgb.assign(36, 128);
    for (const char* name : {"0.000000", "0.033333", "1"}) {
      mmh::WriteDepthPng16(f / "depth" / (std::string(name) + ".png"), depth);
      mmh::WriteRgbPng(f / "rgb" / (std::string(name) + ".png"), rgb);
    }
    return f;
  }();
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const std::filesystem::path& folder = Folder();
  std::string_view rest{reinterpret_cast<const char*>(data), size};
  for (const char* name : {"rgb.txt", "depth.txt", "groundtruth.txt", "camera.json"}) {
    const auto [part, tail] = fuzz::SplitInput(rest, "\n----\n");
    std::filesystem::remove(folder / name);
    if (!part.empty()) fuzz::WriteInput(std::string("seq/") + name, part);
    rest = tail;
  }
  fuzz::ExpectReadOrInputError([&] {
    RgbdFolderReader reader(folder);
    for (int i = 0; i < reader.size() && i < 4; ++i) {
      fuzz::ExpectReadOrInputError([&] { reader.Read(i); });
    }
    reader.ReadGroundtruth();
  });
  return 0;
}
