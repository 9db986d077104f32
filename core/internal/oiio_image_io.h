// The image readers and writers of core/image_io.h as OpenImageIO implements them, built as a
// plugin, libmmh_oiio_image_io.so, which core/image_io.cc loads with dlopen on the first image
// read or written: Debian's OpenImageIO brings about 260 shared libraries (OpenVDB, ffmpeg, GDAL,
// DICOM...) and costs every process 0.2-0.6 s and 130 MB at start otherwise, and most mmh
// processes read or write no image (docs/architecture.md, "Start-up").
//
// The plugin holds its own copy of core/error.cc and core/error_text.cc (its InputErrors are
// caught by the program like any other: the C++ runtime matches exception types by name).
#pragma once

#include <filesystem>

#include "core/image_io.h"

namespace mmh::internal {

// The functions of core/image_io.h, same contracts.
struct ImageIoFunctions {
  DepthImage (*read_depth_png16)(const std::filesystem::path& path);
  void (*write_depth_png16)(const std::filesystem::path& path, const DepthImage& image,
                            int compression);
  RgbImage (*read_rgb_image)(const std::filesystem::path& path);
  void (*write_rgb_png)(const std::filesystem::path& path, const RgbImage& image, int compression);
  DepthImage (*read_nyu_raw_disparity)(const std::filesystem::path& path);
  DepthImage (*read_sun_depth)(const std::filesystem::path& path);
};

// The plugin's exported entry point: const ImageIoFunctions* MmhOiioImageIo().
inline constexpr const char* kImageIoSymbol = "MmhOiioImageIo";

}  // namespace mmh::internal
