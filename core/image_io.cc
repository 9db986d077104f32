#include "core/image_io.h"

#include "core/internal/oiio_image_io.h"
#include "core/plugin.h"

namespace mmh {
namespace {

// OpenImageIO is loaded on the first image read or written (core/internal/oiio_image_io.h).
const internal::ImageIoFunctions& Oiio() {
  static const internal::ImageIoFunctions* functions =
      reinterpret_cast<const internal::ImageIoFunctions* (*)()>(
          PluginSymbol(MMH_OIIO_IMAGE_IO_PLUGIN, internal::kImageIoSymbol))();
  return *functions;
}

}  // namespace

DepthImage ReadDepthPng16(const std::filesystem::path& path) {
  return Oiio().read_depth_png16(path);
}

void WriteDepthPng16(const std::filesystem::path& path, const DepthImage& image, int compression) {
  Oiio().write_depth_png16(path, image, compression);
}

RgbImage ReadRgbImage(const std::filesystem::path& path) { return Oiio().read_rgb_image(path); }

void WriteRgbPng(const std::filesystem::path& path, const RgbImage& image, int compression) {
  Oiio().write_rgb_png(path, image, compression);
}

DepthImage ReadNyuRawDisparity(const std::filesystem::path& path) {
  return Oiio().read_nyu_raw_disparity(path);
}

DepthImage ReadSunDepth(const std::filesystem::path& path) {
  return Oiio().read_sun_depth(path);
}

}  // namespace mmh
