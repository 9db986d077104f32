// The MAT-file reader against a file built byte by byte from the format's specification, the real
// YCB-Video -meta.mat files (values checked against the dataset's published camera), the text
// export, and damaged files (InputError naming the file, never a crash).
#include "track/mat_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::track {
namespace {

namespace fs = std::filesystem;
using test_util::ErrorOf;
using test_util::TempDir;
using test_util::WriteText;
using ::testing::HasSubstr;

const fs::path kYcb = fs::path(MMH_TEST_DATA_DIR) / "real" / "ycbv" / "data" / "0000";

void Put32(std::string* s, uint32_t v) { s->append(reinterpret_cast<const char*>(&v), 4); }
void PutPadded(std::string* s, const std::string& data) {
  s->append(data);
  s->append((8 - data.size() % 8) % 8, '\0');
}

// An uncompressed level-5 file holding double `name` (2x3) with 1..6 column-major, written as
// the specification's figures show it.
std::string TinyMatFile(const std::string& name) {
  std::string header = "MATLAB 5.0 MAT-file, written by hand";
  header.resize(116, ' ');
  header.append(8, '\0');
  header += std::string("\x00\x01", 2) + "IM";
  std::string body;
  Put32(&body, 6);  // array flags: miUINT32, 8 bytes, class mxDOUBLE (6)
  Put32(&body, 8);
  Put32(&body, 6);
  Put32(&body, 0);
  Put32(&body, 5);  // dimensions: miINT32, 2 x 3
  Put32(&body, 8);
  Put32(&body, 2);
  Put32(&body, 3);
  Put32(&body, 1);  // name: miINT8
  Put32(&body, static_cast<uint32_t>(name.size()));
  PutPadded(&body, name);
  Put32(&body, 9);  // real part: miDOUBLE, 6 values
  Put32(&body, 48);
  for (int i = 1; i <= 6; ++i) {
    const double v = i;
    body.append(reinterpret_cast<const char*>(&v), 8);
  }
  std::string file = header;
  Put32(&file, 14);  // miMATRIX
  Put32(&file, static_cast<uint32_t>(body.size()));
  return file + body;
}

TEST(MatFileTest, ReadsAnArrayWrittenFromTheSpecification) {
  TempDir dir;
  WriteText(dir / "tiny.mat", TinyMatFile("abc"));
  const MatFile file = ReadMatFile(dir / "tiny.mat");
  const MatArray& a = file.Get("abc", {2, 3}, dir / "tiny.mat");
  EXPECT_EQ(a.at(0, 0), 1);
  EXPECT_EQ(a.at(1, 0), 2);
  EXPECT_EQ(a.at(0, 2), 5);
  EXPECT_EQ(a.at(1, 2), 6);
  EXPECT_THAT(ErrorOf([&] { file.Get("abc", {3, 2}, dir / "tiny.mat"); }),
              HasSubstr("got 2x3, expected dimensions 3x2"));
  EXPECT_THAT(ErrorOf([&] { file.Get("poses", {3, 4}, dir / "tiny.mat"); }),
              HasSubstr("variable 'poses' is missing"));
}

TEST(MatFileTest, ReadsYcbVideoMeta) {
  const MatFile meta = ReadMatFile(kYcb / "000001-meta.mat");
  const fs::path f = kYcb / "000001-meta.mat";
  EXPECT_EQ(meta.Get("factor_depth", {1, 1}, f).values[0], 10000);
  const MatArray& k = meta.Get("intrinsic_matrix", {3, 3}, f);
  // The published Asus camera of videos 0-59 (cameras/asus-uw.json: fu, fv, u0, v0).
  EXPECT_NEAR(k.at(0, 0), 1066.778, 1e-3);
  EXPECT_NEAR(k.at(1, 1), 1067.487, 1e-3);
  EXPECT_NEAR(k.at(0, 2), 312.9869, 1e-4);
  EXPECT_NEAR(k.at(1, 2), 241.3109, 1e-4);
  EXPECT_EQ(k.at(2, 2), 1);
  EXPECT_EQ(meta.Get("cls_indexes", {3, 1}, f).values, (std::vector<double>{8, 14, 21}));
  const MatArray& poses = meta.Get("poses", {3, 4, 3}, f);
  // Each pose's rotation is orthonormal (an independent check of the column-major layout).
  for (int j = 0; j < 3; ++j) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        double dot = 0;
        for (int r = 0; r < 3; ++r) dot += poses.at(r, a, j) * poses.at(r, b, j);
        EXPECT_NEAR(dot, a == b ? 1.0 : 0.0, 1e-5);
      }
    }
    EXPECT_GT(poses.at(2, 3, j), 0.3);  // in front of the camera
  }
  EXPECT_EQ(meta.Get("vertmap", {480, 640, 3}, f).size(), 480 * 640 * 3);
}

TEST(MatFileTest, TextExportReadsTheSame) {
  TempDir dir;
  WriteText(dir / "m.txt", "# exported\nfactor_depth: 1 1\n10000\nposes: 3 4 1\n"
                           "1 0 0  0 1 0  0 0 1  0.1 0.2 0.5\ncls_indexes: 1 1\n8\n");
  const MatFile text = ReadMatText(dir / "m.txt");
  EXPECT_EQ(text.Get("factor_depth", {1, 1}, dir / "m.txt").values[0], 10000);
  EXPECT_EQ(text.Get("poses", {3, 4, 1}, dir / "m.txt").at(2, 3), 0.5);
  WriteText(dir / "bad.txt", "poses: 3 4\n1 2 3\n");
  EXPECT_THAT(ErrorOf([&] { ReadMatText(dir / "bad.txt"); }),
              HasSubstr("bad.txt:1: variable 'poses' has 3 values, expected 12"));
  WriteText(dir / "nan.txt", "poses: 1 1\nx1\n");
  EXPECT_THAT(ErrorOf([&] { ReadMatText(dir / "nan.txt"); }), HasSubstr("nan.txt:2"));
}

TEST(MatFileTest, DamagedFilesAreInputErrorsNamingTheFile) {
  TempDir dir;
  std::ifstream in(kYcb / "000001-meta.mat", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  WriteText(dir / "truncated.mat", bytes.substr(0, bytes.size() / 2));
  EXPECT_THAT(ErrorOf([&] { ReadMatFile(dir / "truncated.mat"); }),
              HasSubstr("truncated.mat: not a valid MAT-file"));
  std::string corrupt = bytes;
  for (size_t i = 200; i < 400; ++i) corrupt[i] = static_cast<char>(i);
  WriteText(dir / "corrupt.mat", corrupt);
  EXPECT_THAT(ErrorOf([&] { ReadMatFile(dir / "corrupt.mat"); }), HasSubstr("corrupt.mat"));
  // Dimensions whose product no element could hold (and that would overflow a 64-bit count with
  // a third one) are refused before any value is read.
  std::string huge = TinyMatFile("abc");
  const int32_t side = 2147483647;
  std::memcpy(&huge[160], &side, 4);
  std::memcpy(&huge[164], &side, 4);
  WriteText(dir / "huge.mat", huge);
  EXPECT_THAT(ErrorOf([&] { ReadMatFile(dir / "huge.mat"); }),
              HasSubstr("dimensions of more than 2^32 elements"));
  WriteText(dir / "huge.txt", "poses: 4294967296 4294967296 4294967296\n1\n");
  EXPECT_THAT(ErrorOf([&] { ReadMatText(dir / "huge.txt"); }),
              HasSubstr("huge.txt:1: dimensions of 'poses'"));
  WriteText(dir / "text.mat", "hello");
  EXPECT_THAT(ErrorOf([&] { ReadMatFile(dir / "text.mat"); }),
              HasSubstr("text.mat: not a level-5 MAT-file"));
  EXPECT_THAT(ErrorOf([&] { ReadMatFile(dir / "missing.mat"); }), HasSubstr("missing.mat"));
}

}  // namespace
}  // namespace mmh::track
