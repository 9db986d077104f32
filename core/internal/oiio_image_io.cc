// The OpenImageIO plugin of core/image_io.h (core/internal/oiio_image_io.h).
#include "core/internal/oiio_image_io.h"

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/typedesc.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <system_error>

#include "core/error.h"
#include "core/error_text.h"
#include "core/resource_limits.h"
#include "core/temporary_name.h"

namespace mmh::internal {
namespace {

namespace fs = std::filesystem;

// An OpenImageIO error message without its trailing new line, for our one-line messages.
std::string OiioMessage(std::string message) {
  while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back()))) {
    message.pop_back();
  }
  if (message.empty()) return "no details";
  return message;
}

// Fails with a clear message for a missing path or a folder, before OpenImageIO gives a vaguer
// one.
void RequireReadableFile(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    ThrowBadValue(path.string(), "a path that does not exist", "an existing image file");
  }
  if (fs::is_directory(path, ec)) ThrowBadValue(path.string(), "a folder", "an image file");
}

void RequireSize(const fs::path& path, int width, int height) {
  if (width < 1 || width > kMaxImageSide || height < 1 || height > kMaxImageSide) {
    ThrowBadValue(path.string(),
                  "an image of " + std::to_string(width) + "x" + std::to_string(height) + " px",
                  "a size in [1, 16384] px per side");
  }
}

std::string DescribeFormat(const OIIO::ImageSpec& spec, const std::string& format_name) {
  return "a " + std::to_string(spec.nchannels) + "-channel " + std::string(spec.format.c_str()) +
         " " + format_name + " image";
}

// A PNG's chunk structure (length, type, data, CRC; IHDR first, IEND last), checked before
// libpng reads it: libpng prints its errors to stderr ("libpng error: ... hit end of file"), even
// under --quiet, and a truncated file is the common case. No-op for other formats.
void CheckPngChunks(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char signature[8] = {};
  if (!in.read(signature, 8) || std::string(signature, 8) != "\x89PNG\r\n\x1A\n") return;
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) return;
  std::uintmax_t pos = 8;
  bool first = true;
  while (true) {
    unsigned char header[8];
    if (pos + 8 > size || !in.read(reinterpret_cast<char*>(header), 8)) {
      ThrowBadValue(path.string(),
                    "a truncated PNG (" + std::to_string(size) + " bytes, no IEND chunk)",
                    "a complete PNG file");
    }
    const std::uintmax_t length =
        (std::uintmax_t{header[0]} << 24) | (header[1] << 16) | (header[2] << 8) | header[3];
    const std::string type(reinterpret_cast<const char*>(header) + 4, 4);
    if ((first && type != "IHDR") || length > 0x7FFFFFFF) {
      ThrowBadValue(path.string(),
                    "a corrupt PNG (chunk " + Quote(type) + " at byte " + std::to_string(pos) + ")",
                    "a valid PNG file");
    }
    first = false;
    const std::uintmax_t end = pos + 12 + length;
    if (end > size) {
      ThrowBadValue(path.string(),
                    "a truncated PNG (chunk " + Quote(type) + " at byte " + std::to_string(pos) +
                        " needs " + std::to_string(end) + " bytes, the file has " +
                        std::to_string(size) + ")",
                    "a complete PNG file");
    }
    // The chunk's CRC (of its type and data, PNG spec 5.3): libpng checks it too, but prints its
    // complaint about a damaged IDAT to stderr before OpenImageIO reports the failure.
    uLong crc = crc32(0L, header + 4, 4);
    char buffer[65536];
    for (std::uintmax_t left = length; left > 0;) {
      const auto n = static_cast<std::streamsize>(std::min<std::uintmax_t>(left, sizeof buffer));
      if (!in.read(buffer, n)) return;  // (cannot happen: the size was checked)
      crc = crc32(crc, reinterpret_cast<const Bytef*>(buffer), static_cast<uInt>(n));
      left -= static_cast<std::uintmax_t>(n);
    }
    unsigned char stored[4];
    if (!in.read(reinterpret_cast<char*>(stored), 4)) return;
    const uLong expected = (uLong{stored[0]} << 24) | (uLong{stored[1]} << 16) |
                           (uLong{stored[2]} << 8) | uLong{stored[3]};
    if (crc != expected) {
      ThrowBadValue(path.string(),
                    "a corrupt PNG (chunk " + Quote(type) + " at byte " + std::to_string(pos) +
                        " fails its CRC)",
                    "a valid PNG file");
    }
    if (type == "IEND") return;
    pos = end;
  }
}

// Opens `path` with OpenImageIO; InputError naming the path when it cannot.
std::unique_ptr<OIIO::ImageInput> OpenImage(const fs::path& path,
                                            const OIIO::ImageSpec* config = nullptr) {
  RequireReadableFile(path);
  CheckPngChunks(path);
  auto input = OIIO::ImageInput::open(path.string(), config);
  if (!input) {
    ThrowBadValue(path.string(), "an unreadable image (" + OiioMessage(OIIO::geterror()) + ")",
                  "a readable, complete image file");
  }
  return input;
}

// Reads all pixels of the first subimage as `type`; a truncated or corrupt file is an InputError.
template <class T>
std::vector<T> ReadPixels(OIIO::ImageInput& input, const fs::path& path, OIIO::TypeDesc type) {
  const OIIO::ImageSpec& spec = input.spec();
  std::vector<T> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  if (!input.read_image(0, 0, 0, spec.nchannels, type, pixels.data())) {
    const std::string message = OiioMessage(input.geterror());
    input.close();
    ThrowBadValue(path.string(), "a truncated or corrupt image (" + message + ")",
                  "a complete, valid image file");
  }
  // Some decoders report trouble without failing the read; treat that as corruption too.
  if (input.has_error()) {
    const std::string message = OiioMessage(input.geterror());
    input.close();
    ThrowBadValue(path.string(), "a corrupt image (" + message + ")", "a valid image file");
  }
  input.close();
  return pixels;
}

OIIO::ImageSpec PngSpec(int width, int height, int channels, OIIO::TypeDesc format,
                        int compression) {
  if (compression < 0 || compression > 9) {
    ThrowBadValue("PNG compression", std::to_string(compression), "a zlib level in [0, 9]");
  }
  OIIO::ImageSpec spec(width, height, channels, format);
  spec.attribute("png:compressionLevel", compression);
  return spec;
}

// Writes one image through OpenImageIO to a temporary file, then renames it over `path`.
void WriteImageAtomically(const fs::path& path, const OIIO::ImageSpec& spec, const void* pixels) {
  // The extension kept: OpenImageIO picks the format by it.
  const fs::path temporary = TemporaryBeside(path, /*keep_extension=*/true);
  auto remove_temporary = [&] {
    std::error_code ignored;
    fs::remove(temporary, ignored);
  };
  auto output = OIIO::ImageOutput::create(temporary.string());
  if (!output) {
    ThrowBadValue(path.string(), "no image writer (" + OiioMessage(OIIO::geterror()) + ")",
                  "a file name ending in an image extension such as .png");
  }
  if (!output->open(temporary.string(), spec)) {
    const std::string message = OiioMessage(output->geterror());
    remove_temporary();
    ThrowBadValue(path.string(), "an unwritable path (" + message + ")",
                  "a writable file in an existing folder");
  }
  const bool written = output->write_image(spec.format, pixels);
  const bool closed = output->close();
  if (!written || !closed) {
    const std::string message = OiioMessage(output->geterror());
    output.reset();
    remove_temporary();
    ThrowBadValue(path.string(), "a failed write (" + message + ")",
                  "enough space to write the file");
  }
  output.reset();
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) {
    remove_temporary();
    ThrowBadValue(path.string(), "a failed rename (" + ec.message() + ")", "a writable folder");
  }
}

// Reads a whole binary file; InputError naming the path when it cannot.
std::string ReadBinaryFile(const fs::path& path) {
  RequireReadableFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ThrowBadValue(path.string(), "an unreadable file (" + std::string(std::strerror(errno)) + ")",
                  "a readable file");
  }
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) ThrowBadValue(path.string(), "a failed read", "a readable file");
  return bytes;
}

// Netpbm header tokeniser: white space separates tokens, '#' starts a comment to the end of line.
class PnmHeader {
 public:
  PnmHeader(const std::string& bytes, const fs::path& path) : bytes_(bytes), path_(path) {}

  std::string Token(const char* what) {
    while (pos_ < bytes_.size()) {
      const unsigned char c = static_cast<unsigned char>(bytes_[pos_]);
      if (c == '#') {
        while (pos_ < bytes_.size() && bytes_[pos_] != '\n' && bytes_[pos_] != '\r') ++pos_;
      } else if (std::isspace(c)) {
        ++pos_;
      } else {
        break;
      }
    }
    const size_t start = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_])) &&
           bytes_[pos_] != '#') {
      ++pos_;
    }
    if (start == pos_) {
      ThrowBadValue(path_.string() + ", PGM header",
                    "the end of the file before the " + std::string(what),
                    "a header 'P5 width height maxval'");
    }
    return bytes_.substr(start, pos_ - start);
  }

  int Number(const char* what, int low, int high) {
    const std::string token = Token(what);
    int value = 0;
    bool ok = !token.empty() && token.size() <= 6;
    for (char c : token) ok = ok && std::isdigit(static_cast<unsigned char>(c));
    if (ok) value = std::stoi(token);
    if (!ok || value < low || value > high) {
      ThrowBadValue(path_.string() + ", PGM " + what, "'" + token + "'",
                    "an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
    }
    return value;
  }

  // The header ends with exactly one white-space character before the samples.
  size_t DataStart() {
    if (pos_ >= bytes_.size() || !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) {
      ThrowBadValue(path_.string() + ", PGM header", "no white space after maxval",
                    "one white-space character between the header and the samples");
    }
    return pos_ + 1;
  }

 private:
  const std::string& bytes_;
  const fs::path& path_;
  size_t pos_ = 0;
};

}  // namespace

DepthImage ReadDepthPng16(const fs::path& path) {
  auto input = OpenImage(path);
  const OIIO::ImageSpec spec = input->spec();
  const std::string format_name = input->format_name();
  if (format_name != "png" || spec.nchannels != 1 || spec.format != OIIO::TypeDesc::UINT16) {
    input->close();
    ThrowBadValue(path.string(), DescribeFormat(spec, format_name),
                  "a 16-bit single-channel PNG (depth image)");
  }
  RequireSize(path, spec.width, spec.height);
  DepthImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.values = ReadPixels<uint16_t>(*input, path, OIIO::TypeDesc::UINT16);
  return image;
}

void WriteDepthPng16(const fs::path& path, const DepthImage& image, int compression) {
  RequireSize(path, image.width, image.height);
  const size_t expected = static_cast<size_t>(image.width) * image.height;
  if (image.values.size() != expected) {
    ThrowBadValue(path.string() + ", depth values", std::to_string(image.values.size()),
                  std::to_string(expected) + " = width x height");
  }
  WriteImageAtomically(path,
                       PngSpec(image.width, image.height, 1, OIIO::TypeDesc::UINT16, compression),
                       image.values.data());
}

RgbImage ReadRgbImage(const fs::path& path) {
  // Alpha is dropped, so it must not have been multiplied into the colour first.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto input = OpenImage(path, &config);
  const OIIO::ImageSpec spec = input->spec();
  const std::string format_name = input->format_name();
  const int channels = spec.nchannels;
  if (channels < 1 || channels > 4) {
    input->close();
    ThrowBadValue(path.string(), DescribeFormat(spec, format_name),
                  "a grey, grey+alpha, RGB or RGBA image");
  }
  RequireSize(path, spec.width, spec.height);
  // OpenImageIO converts 16-bit and float samples to 8 bit with rounding.
  const std::vector<uint8_t> pixels = ReadPixels<uint8_t>(*input, path, OIIO::TypeDesc::UINT8);
  RgbImage image;
  image.width = spec.width;
  image.height = spec.height;
  const size_t count = static_cast<size_t>(spec.width) * spec.height;
  image.rgb.resize(count * 3);
  const bool grey = channels <= 2;
  for (size_t i = 0; i < count; ++i) {
    const uint8_t* p = &pixels[i * channels];
    image.rgb[3 * i + 0] = p[0];
    image.rgb[3 * i + 1] = grey ? p[0] : p[1];
    image.rgb[3 * i + 2] = grey ? p[0] : p[2];
  }
  return image;
}

void WriteRgbPng(const fs::path& path, const RgbImage& image, int compression) {
  RequireSize(path, image.width, image.height);
  const size_t expected = static_cast<size_t>(image.width) * image.height * 3;
  if (image.rgb.size() != expected) {
    ThrowBadValue(path.string() + ", rgb bytes", std::to_string(image.rgb.size()),
                  std::to_string(expected) + " = width x height x 3");
  }
  WriteImageAtomically(path,
                       PngSpec(image.width, image.height, 3, OIIO::TypeDesc::UINT8, compression),
                       image.rgb.data());
}

DepthImage ReadNyuRawDisparity(const fs::path& path) {
  const std::string bytes = ReadBinaryFile(path);
  PnmHeader header(bytes, path);
  const std::string magic = header.Token("magic number");
  if (magic != "P5") {
    ThrowBadValue(path.string() + ", PGM magic number", "'" + magic.substr(0, 16) + "'",
                  "'P5' (binary greyscale PGM)");
  }
  DepthImage image;
  image.width = header.Number("width", 1, kMaxImageSide);
  image.height = header.Number("height", 1, kMaxImageSide);
  // Two bytes per sample need maxval > 255 (the NYU dumps and fakenect write 65535).
  header.Number("maxval", 256, 65535);
  const size_t start = header.DataStart();
  const size_t count = static_cast<size_t>(image.width) * image.height;
  const size_t available = bytes.size() - std::min(start, bytes.size());
  if (available != 2 * count) {
    ThrowBadValue(path.string(),
                  std::to_string(available) + " bytes of samples" +
                      (available < 2 * count ? " (a truncated file)" : " (trailing bytes)"),
                  std::to_string(2 * count) + " = width x height x 2 bytes");
  }
  image.values.resize(count);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + start);
  for (size_t i = 0; i < count; ++i) {
    // Little-endian, whatever the host: the NYU toolbox and fakenect dump the driver's buffer.
    const uint16_t value = static_cast<uint16_t>(data[2 * i] | (data[2 * i + 1] << 8));
    if (value > 2047) {
      ThrowBadValue(path.string() + ", pixel (" + std::to_string(i % image.width) + ", " +
                        std::to_string(i / image.width) + ")",
                    std::to_string(value),
                    "a raw 11-bit disparity in [0, 2047] stored little-endian (is this a "
                    "big-endian PGM or not a raw Kinect dump?)");
    }
    image.values[i] = value;
  }
  return image;
}

DepthImage ReadSunDepth(const fs::path& path) {
  DepthImage image = ReadDepthPng16(path);
  for (uint16_t& v : image.values) {
    v = static_cast<uint16_t>((v >> 3) | (v << 13));
  }
  return image;
}

}  // namespace mmh::internal

// The entry point core/image_io.cc looks up with dlsym.
extern "C" __attribute__((visibility("default"))) const mmh::internal::ImageIoFunctions*
MmhOiioImageIo() {
  using namespace mmh::internal;
  static const ImageIoFunctions functions = {ReadDepthPng16,      WriteDepthPng16,
                                             ReadRgbImage,        WriteRgbPng,
                                             ReadNyuRawDisparity, ReadSunDepth};
  return &functions;
}
