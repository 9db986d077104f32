// Shared by the libFuzzer targets: the readers take files, so each input is written to a file
// (in /dev/shm when it exists: no disk writes per input) and the reader runs on it. An InputError
// is the expected answer to bad input; any other exception, a crash, a sanitizer report, a leak
// or a hang (> 1 s per input) is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/image_io.h"

namespace mmh::fuzz {

// A folder of this process for the inputs (removed by the OS's tmp cleaning; files are reused).
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path base =
        std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
    std::filesystem::path d = base / ("mmh_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes `bytes` to ScratchDir()/name and returns the path.
inline std::filesystem::path WriteInput(const std::string& name, std::string_view bytes) {
  const std::filesystem::path path = ScratchDir() / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

// Runs `read` and accepts InputError (the right answer to bad input); everything else escapes.
template <class F>
void ExpectReadOrInputError(F&& read) {
  try {
    read();
  } catch (const InputError&) {
  }
}

// Splits an input in two at the first occurrence of `separator` (for targets that read two
// files); the second part is empty without one.
inline std::pair<std::string_view, std::string_view> SplitInput(std::string_view data,
                                                                std::string_view separator) {
  const std::size_t at = data.find(separator);
  if (at == std::string_view::npos) return {data, {}};
  return {data.substr(0, at), data.substr(at + separator.size())};
}

// For targets that read several files of one folder: splits `data` at "\n----\n" into one part
// per name, in order, and writes each non-empty part to ScratchDir()/folder/name (a file whose part
// is empty or missing is removed, so the reader sees it absent).
inline void WriteParts(std::string_view data, const std::string& folder,
                       std::initializer_list<const char*> names) {
  for (const char* name : names) {
    const auto [part, tail] = SplitInput(data, "\n----\n");
    std::filesystem::remove(ScratchDir() / folder / name);
    if (!part.empty()) WriteInput(folder + "/" + name, part);
    data = tail;
  }
}

// Writes a small valid frame (4 x 3 px, 16-bit depth 5000 and grey colour PNGs) as
// folder/depth/STEM.png and folder/rgb/STEM.png for each stem, so that readers of a folder's
// index get as far as reading its images. Each is read back once: the first colour read starts
// OpenImageIO (plugin loading, about 1.5 s under ASan), which a target should pay in
// LLVMFuzzerInitialize, not in its first input's -timeout.
inline void WriteTinyFrames(const std::filesystem::path& folder,
                            std::initializer_list<const char*> stems) {
  std::filesystem::create_directories(folder / "rgb");
  std::filesystem::create_directories(folder / "depth");
  DepthImage depth;
  depth.width = 4, depth.height = 3;
  depth.values.assign(12, 5000);
  RgbImage rgb;
  rgb.width = 4, rgb.height = 3;
  rgb.rgb.assign(36, 128);
  for (const char* stem : stems) {
    WriteDepthPng16(folder / "depth" / (std::string(stem) + ".png"), depth);
    WriteRgbPng(folder / "rgb" / (std::string(stem) + ".png"), rgb);
    ReadDepthPng16(folder / "depth" / (std::string(stem) + ".png"));
    ReadRgbImage(folder / "rgb" / (std::string(stem) + ".png"));
  }
}

}  // namespace mmh::fuzz
