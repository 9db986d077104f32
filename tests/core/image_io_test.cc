// Tests of core/image_io.h: round trips, conversions, error messages for bad files, and the
// readers of the public datasets on the real sample frames (skipped when they are absent).
#include "core/image_io.h"

#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// The real sample frames of DESIGN.md ("Kinect v1 model"), outside the repository.
const fs::path kRealRgbd = "/work/shared/data/real-rgbd";

using test_util::ErrorOf;
using test_util::ReadBytes;
using test_util::TempDir;

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  ASSERT_TRUE(out.good());
}

DepthImage RandomDepth(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  DepthImage image{width, height, {}};
  image.values.resize(static_cast<size_t>(width) * height);
  for (auto& v : image.values) v = static_cast<uint16_t>(rng());
  image.values[0] = 0;
  image.values[1] = 65535;
  return image;
}

RgbImage RandomRgb(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  RgbImage image{width, height, {}};
  image.rgb.resize(static_cast<size_t>(width) * height * 3);
  for (auto& v : image.rgb) v = static_cast<uint8_t>(rng());
  return image;
}

// Writes `pixels` with OpenImageIO directly, to make files of other layouts than ours.
template <class T>
void WriteWithOiio(const fs::path& path, int width, int height, int channels, OIIO::TypeDesc type,
                   const std::vector<T>& pixels) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(width, height, channels, type);
  // The pixels are straight (unpremultiplied) colour, as PNG stores it.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  ASSERT_TRUE(out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(type, pixels.data()));
  ASSERT_TRUE(out->close());
}

TEST(ImageIoTest, DepthRoundTripIsBitExactAndDeterministic) {
  TempDir dir;
  const DepthImage image = RandomDepth(37, 23, 1);
  WriteDepthPng16(dir / "a.png", image);
  WriteDepthPng16(dir / "b.png", image);
  const DepthImage back = ReadDepthPng16(dir / "a.png");
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 23);
  EXPECT_EQ(back.values, image.values);
  // The same image always gives the same bytes (no time stamps in the file).
  EXPECT_EQ(ReadBytes(dir / "a.png"), ReadBytes(dir / "b.png"));
  // No temporary files are left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 2);
}

TEST(ImageIoTest, RgbRoundTripIsBitExact) {
  TempDir dir;
  const RgbImage image = RandomRgb(31, 17, 2);
  WriteRgbPng(dir / "c.png", image);
  const RgbImage back = ReadRgbImage(dir / "c.png");
  EXPECT_EQ(back.width, 31);
  EXPECT_EQ(back.height, 17);
  EXPECT_EQ(back.rgb, image.rgb);
}

TEST(ImageIoTest, WriteReplacesAnExistingFile) {
  TempDir dir;
  WriteDepthPng16(dir / "d.png", RandomDepth(8, 8, 3));
  const DepthImage second = RandomDepth(5, 4, 4);
  WriteDepthPng16(dir / "d.png", second);
  EXPECT_EQ(ReadDepthPng16(dir / "d.png").values, second.values);
}

TEST(ImageIoTest, RgbReaderConvertsGreyRgbaAnd16Bit) {
  TempDir dir;
  WriteWithOiio<uint8_t>(dir / "grey.png", 2, 1, 1, OIIO::TypeDesc::UINT8, {10, 200});
  RgbImage grey = ReadRgbImage(dir / "grey.png");
  EXPECT_EQ(grey.rgb, (std::vector<uint8_t>{10, 10, 10, 200, 200, 200}));

  // Alpha is dropped without premultiplying it into the colour.
  WriteWithOiio<uint8_t>(dir / "rgba.png", 2, 1, 4, OIIO::TypeDesc::UINT8,
                         {1, 2, 3, 0, 250, 251, 252, 128});
  RgbImage rgba = ReadRgbImage(dir / "rgba.png");
  EXPECT_EQ(rgba.rgb, (std::vector<uint8_t>{1, 2, 3, 250, 251, 252}));

  WriteWithOiio<uint16_t>(dir / "rgb16.png", 1, 1, 3, OIIO::TypeDesc::UINT16,
                          {0, 65535, 257 * 100});
  RgbImage rgb16 = ReadRgbImage(dir / "rgb16.png");
  EXPECT_EQ(rgb16.rgb, (std::vector<uint8_t>{0, 255, 100}));

  WriteWithOiio<uint8_t>(dir / "p.ppm", 1, 2, 3, OIIO::TypeDesc::UINT8, {9, 8, 7, 6, 5, 4});
  EXPECT_EQ(ReadRgbImage(dir / "p.ppm").rgb, (std::vector<uint8_t>{9, 8, 7, 6, 5, 4}));
}

TEST(ImageIoTest, MissingFileIsAnInputErrorNamingThePath) {
  TempDir dir;
  const std::string message = ErrorOf([&] { ReadDepthPng16(dir / "nope.png"); });
  EXPECT_THAT(message, HasSubstr("nope.png"));
  EXPECT_THAT(message, HasSubstr("does not exist"));
  EXPECT_THAT(ErrorOf([&] { ReadRgbImage(dir / "nope.jpg"); }), HasSubstr("does not exist"));
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "nope.pgm"); }), HasSubstr("does not exist"));
  EXPECT_THAT(ErrorOf([&] { ReadDepthPng16(dir.path()); }), HasSubstr("a folder"));
}

TEST(ImageIoTest, TruncatedPngIsAnInputErrorNotACrash) {
  TempDir dir;
  WriteDepthPng16(dir / "full.png", RandomDepth(64, 48, 5));
  WriteRgbPng(dir / "full_rgb.png", RandomRgb(64, 48, 6));
  for (const char* name : {"full.png", "full_rgb.png"}) {
    const std::string bytes = ReadBytes(dir / name);
    WriteBytes(dir / "half.png", bytes.substr(0, bytes.size() / 2));
    const std::string message = std::string(name) == "full.png"
                                    ? ErrorOf([&] { ReadDepthPng16(dir / "half.png"); })
                                    : ErrorOf([&] { ReadRgbImage(dir / "half.png"); });
    EXPECT_THAT(message, HasSubstr("half.png")) << name;
    EXPECT_THAT(message, HasSubstr("expected a")) << name;
    // Only the header survives.
    WriteBytes(dir / "head.png", bytes.substr(0, 40));
    EXPECT_THAT(ErrorOf([&] { ReadDepthPng16(dir / "head.png"); }), HasSubstr("head.png"));
  }
  WriteBytes(dir / "garbage.png", "this is not a PNG at all");
  EXPECT_THAT(ErrorOf([&] { ReadDepthPng16(dir / "garbage.png"); }), HasSubstr("garbage.png"));
  WriteBytes(dir / "empty.png", "");
  EXPECT_THAT(ErrorOf([&] { ReadRgbImage(dir / "empty.png"); }), HasSubstr("empty.png"));
}

// Damaged compressed data (a flipped byte inside IDAT): the chunk's CRC names it before libpng,
// which would print its own complaint to stderr even under --quiet, reads the file.
TEST(ImageIoTest, DamagedPngDataFailsItsCrcWithoutLibpngPrinting) {
  TempDir dir;
  WriteDepthPng16(dir / "full.png", RandomDepth(64, 48, 5));
  std::string bytes = ReadBytes(dir / "full.png");
  const std::size_t idat = bytes.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 20] = static_cast<char>(bytes[idat + 20] ^ 0x5A);
  WriteBytes(dir / "flipped.png", bytes);
  testing::internal::CaptureStderr();
  const std::string message = ErrorOf([&] { ReadDepthPng16(dir / "flipped.png"); });
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_THAT(message, HasSubstr("flipped.png: got a corrupt PNG (chunk 'IDAT' at byte "));
  EXPECT_THAT(message, HasSubstr("fails its CRC"));
  EXPECT_EQ(printed, "");
}

TEST(ImageIoTest, WrongChannelsOrBitDepthForDepthIsAnInputError) {
  TempDir dir;
  WriteWithOiio<uint8_t>(dir / "eight.png", 2, 2, 1, OIIO::TypeDesc::UINT8, {1, 2, 3, 4});
  std::string message = ErrorOf([&] { ReadDepthPng16(dir / "eight.png"); });
  EXPECT_THAT(message, HasSubstr("eight.png: got a 1-channel uint8 png image"));
  EXPECT_THAT(message, HasSubstr("expected a 16-bit single-channel PNG"));
  WriteWithOiio<uint16_t>(dir / "three.png", 1, 1, 3, OIIO::TypeDesc::UINT16, {1, 2, 3});
  EXPECT_THAT(ErrorOf([&] { ReadDepthPng16(dir / "three.png"); }), HasSubstr("3-channel"));
  WriteWithOiio<uint8_t>(dir / "six.tif", 1, 1, 6, OIIO::TypeDesc::UINT8, {1, 2, 3, 4, 5, 6});
  EXPECT_THAT(ErrorOf([&] { ReadRgbImage(dir / "six.tif"); }),
              HasSubstr("expected a grey, grey+alpha, RGB or RGBA image"));
}

TEST(ImageIoTest, WritesCheckSizesAndFolders) {
  TempDir dir;
  DepthImage bad{4, 4, std::vector<uint16_t>(15)};
  EXPECT_THAT(ErrorOf([&] { WriteDepthPng16(dir / "x.png", bad); }),
              HasSubstr("got 15, expected 16 = width x height"));
  RgbImage bad_rgb{2, 2, std::vector<uint8_t>(11)};
  EXPECT_THAT(ErrorOf([&] { WriteRgbPng(dir / "y.png", bad_rgb); }), HasSubstr("got 11"));
  EXPECT_THAT(
      ErrorOf([&] { WriteDepthPng16(dir / "no_such_folder" / "z.png", RandomDepth(2, 2, 7)); }),
      HasSubstr("no_such_folder"));
  if (::geteuid() != 0) {  // root writes anywhere
    fs::create_directories(dir / "locked");
    fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THAT(ErrorOf([&] { WriteRgbPng(dir / "locked" / "z.png", RandomRgb(2, 2, 8)); }),
                HasSubstr("locked"));
    fs::permissions(dir / "locked", fs::perms::owner_all);
  }
}

std::string LittleEndianPgm(int width, int height, const std::vector<uint16_t>& values,
                            const std::string& header_extra = "") {
  std::string bytes =
      "P5" + header_extra + " " + std::to_string(width) + " " + std::to_string(height) + " 65535\n";
  for (uint16_t v : values) {
    bytes.push_back(static_cast<char>(v & 0xff));
    bytes.push_back(static_cast<char>(v >> 8));
  }
  return bytes;
}

TEST(ImageIoTest, NyuRawReaderParsesLittleEndianPgm) {
  TempDir dir;
  WriteBytes(dir / "d.pgm", LittleEndianPgm(3, 2, {0, 1, 700, 1023, 2046, 2047}, "\n# comment\n"));
  const DepthImage image = ReadNyuRawDisparity(dir / "d.pgm");
  EXPECT_EQ(image.width, 3);
  EXPECT_EQ(image.height, 2);
  EXPECT_EQ(image.values, (std::vector<uint16_t>{0, 1, 700, 1023, 2046, 2047}));
}

TEST(ImageIoTest, NyuRawReaderRejectsBadFiles) {
  TempDir dir;
  const std::string good = LittleEndianPgm(2, 2, {1, 2, 3, 4});
  WriteBytes(dir / "trunc.pgm", good.substr(0, good.size() - 3));
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "trunc.pgm"); }),
              HasSubstr("trunc.pgm: got 5 bytes of samples (a truncated file), expected 8"));
  WriteBytes(dir / "long.pgm", good + "xx");
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "long.pgm"); }), HasSubstr("trailing"));
  WriteBytes(dir / "p6.pgm", "P6 2 2 65535\n" + std::string(8, '\0'));
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "p6.pgm"); }),
              HasSubstr("PGM magic number: got 'P6', expected 'P5'"));
  WriteBytes(dir / "eight.pgm", "P5 2 2 255\n" + std::string(4, '\0'));
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "eight.pgm"); }),
              HasSubstr("PGM maxval: got '255', expected an integer in [256, 65535]"));
  WriteBytes(dir / "w.pgm", "P5 -2 2 65535\n");
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "w.pgm"); }), HasSubstr("PGM width"));
  WriteBytes(dir / "short.pgm", "P5 2");
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "short.pgm"); }),
              HasSubstr("the end of the file before the height"));
  // A big-endian file (the PGM convention) shows up as samples above 2047.
  std::string big = "P5 1 1 65535\n";
  big.push_back(0x03);  // 1000 = 0x03e8 big-endian reads as 0xe803 = 59395
  big.push_back(static_cast<char>(0xe8));
  WriteBytes(dir / "big.pgm", big);
  EXPECT_THAT(ErrorOf([&] { ReadNyuRawDisparity(dir / "big.pgm"); }),
              HasSubstr("pixel (0, 0): got 59395"));
}

TEST(ImageIoTest, SunDepthUndoesTheBitRotation) {
  TempDir dir;
  // Stored value v = rotate-left-by-3 of the millimetres.
  const std::vector<uint16_t> mm = {0, 1, 1500, 8191, 65535};
  std::vector<uint16_t> stored;
  for (uint16_t v : mm) stored.push_back(static_cast<uint16_t>((v << 3) | (v >> 13)));
  WriteDepthPng16(dir / "sun.png", DepthImage{5, 1, stored});
  EXPECT_EQ(ReadSunDepth(dir / "sun.png").values, mm);
}

// --- The real sample frames (data/README.md) ------------------------------------------------

double MissingFraction(const DepthImage& image, uint16_t invalid) {
  return static_cast<double>(std::count(image.values.begin(), image.values.end(), invalid)) /
         image.values.size();
}

// The q-quantile of the valid values.
double Quantile(const DepthImage& image, uint16_t invalid, double q) {
  std::vector<uint16_t> valid;
  for (uint16_t v : image.values) {
    if (v != invalid) valid.push_back(v);
  }
  std::sort(valid.begin(), valid.end());
  return valid[static_cast<size_t>(q * (valid.size() - 1))];
}

TEST(ImageIoRealDataTest, Tum) {
  if (!fs::exists(kRealRgbd / "TUM_depth.png")) GTEST_SKIP() << "no " << kRealRgbd;
  const DepthImage depth = ReadDepthPng16(kRealRgbd / "TUM_depth.png");
  ASSERT_EQ(depth.width, 640);
  ASSERT_EQ(depth.height, 480);
  // data/README.md: about 19 % missing.
  EXPECT_NEAR(MissingFraction(depth, 0), 0.19, 0.02);
  // 5000 units = 1 m; OpenNI reports a Kinect v1 from 0.5 m to about 10 m (coarsely far away).
  EXPECT_GT(Quantile(depth, 0, 0.0) / 5000.0, 0.4);
  EXPECT_LT(Quantile(depth, 0, 1.0) / 5000.0, 10.0);
  const double median_m = Quantile(depth, 0, 0.5) / 5000.0;
  EXPECT_GT(median_m, 0.8);
  EXPECT_LT(median_m, 4.0);
  const RgbImage color = ReadRgbImage(kRealRgbd / "TUM_color.png");
  EXPECT_EQ(color.width, 640);
  EXPECT_EQ(color.height, 480);
  EXPECT_EQ(color.rgb.size(), 640u * 480 * 3);
}

TEST(ImageIoRealDataTest, Nyu) {
  if (!fs::exists(kRealRgbd / "NYU_depth.pgm")) GTEST_SKIP() << "no " << kRealRgbd;
  const DepthImage raw = ReadNyuRawDisparity(kRealRgbd / "NYU_depth.pgm");
  ASSERT_EQ(raw.width, 640);
  ASSERT_EQ(raw.height, 480);
  // data/README.md: about 7 % missing (raw 2047).
  EXPECT_NEAR(MissingFraction(raw, 2047), 0.07, 0.02);
  // z = 351.3 / (1092.5 - raw) within the Kinect range.
  const double z_near = 351.3 / (1092.5 - Quantile(raw, 2047, 0.0));
  const double z_far = 351.3 / (1092.5 - Quantile(raw, 2047, 1.0));
  EXPECT_GT(z_near, 0.4);
  EXPECT_LT(z_far, 10.0);
  EXPECT_GT(z_far, z_near);
  const RgbImage color = ReadRgbImage(kRealRgbd / "NYU_color.ppm");
  EXPECT_EQ(color.width, 640);
  EXPECT_EQ(color.height, 480);
}

TEST(ImageIoRealDataTest, Sun) {
  if (!fs::exists(kRealRgbd / "SUN_depth.png")) GTEST_SKIP() << "no " << kRealRgbd;
  const DepthImage depth = ReadSunDepth(kRealRgbd / "SUN_depth.png");
  EXPECT_GT(depth.width, 0);
  EXPECT_GT(depth.height, 0);
  const double near_m = Quantile(depth, 0, 0.0) / 1000.0;
  const double far_m = Quantile(depth, 0, 1.0) / 1000.0;
  EXPECT_GT(near_m, 0.2);
  EXPECT_LT(far_m, 10.0);
  const double median_m = Quantile(depth, 0, 0.5) / 1000.0;
  EXPECT_GT(median_m, 0.5);
  EXPECT_LT(median_m, 6.0);
  const RgbImage color = ReadRgbImage(kRealRgbd / "SUN_color.jpg");
  EXPECT_EQ(color.width, depth.width);
  EXPECT_EQ(color.height, depth.height);
}

}  // namespace
}  // namespace mmh
