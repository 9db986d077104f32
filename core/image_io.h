// Image files of RGB-D sequences: 16-bit depth PNGs (TUM RGB-D), colour images (PNG, JPEG, PPM),
// and the depth encodings of the public Kinect datasets (NYU Depth V2 raw disparity dumps, SUN
// RGB-D's bit-rotated millimetre PNGs). OpenImageIO stays inside image_io.cc.
//
// Every reader checks what it gets (existence, format, size, channel count, bit depth,
// truncation) and throws InputError naming the path, what it found and what it expected. Every
// writer is atomic: it writes a temporary file with the right extension beside the target, then
// renames it over the target, so a crash never leaves a half-written image.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace mmh {

// A single-channel 16-bit image, #height by #width row-major. The unit is the file's: TUM depth
// units (5000 = 1 m), millimetres (SUN RGB-D) or raw 11-bit disparity (NYU, fakenect).
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<uint16_t> values;
};

// An 8-bit colour image, #height by #width by 3 row-major, channel order R, G, B.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

// Reads a 16-bit single-channel PNG (TUM RGB-D depth). An 8-bit, multi-channel, non-PNG,
// truncated or corrupt file is an InputError.
DepthImage ReadDepthPng16(const std::filesystem::path& path);

// zlib's default PNG compression level; 1 writes about 3.5 times faster for files 5-15 % larger
// (measured on rendered 640x480 frames).
inline constexpr int kDefaultPngCompression = 6;

// Writes a 16-bit single-channel PNG atomically. values.size() must be width * height.
// `compression`: zlib level 0 (none) ... 9 (smallest); the pixels are the same at every level.
void WriteDepthPng16(const std::filesystem::path& path, const DepthImage& image,
                     int compression = kDefaultPngCompression);

// Reads a colour image in any format OpenImageIO reads (PNG, JPEG, PPM, ...), 8 or 16 bit;
// grey is replicated to R, G and B, alpha is dropped (unpremultiplied), 16-bit samples are scaled
// to 8 bit.
RgbImage ReadRgbImage(const std::filesystem::path& path);

// Writes an 8-bit RGB PNG atomically. rgb.size() must be width * height * 3.
void WriteRgbPng(const std::filesystem::path& path, const RgbImage& image,
                 int compression = kDefaultPngCompression);

// Reads an NYU Depth V2 raw depth dump (also what libfreenect's fakenect `record` writes): a binary
// PGM (P5, maxval > 255) whose 16-bit samples are stored little-endian, against the PGM
// convention. Values are raw 11-bit disparities, 2047 = invalid (z [m] = 351.3 / (1092.5 - raw)
// with the NYU calibration). A sample above 2047 (the sign of a big-endian file) is an InputError.
DepthImage ReadNyuRawDisparity(const std::filesystem::path& path);

// Reads a SUN RGB-D depth PNG and undoes its 3-bit rotation: depth_mm = (v >> 3) | (v << 13)
// (16-bit). The result is in millimetres, 0 = missing.
DepthImage ReadSunDepth(const std::filesystem::path& path);

}  // namespace mmh
