// Tests of core/mesh_io.h: PLY round trip (geometry, colours, scale), OBJ with and without
// materials, vertex colours, the PLY and OBJ variants real models use (checked by hand and against
// assimp's reading of the same files, an independent reader), and the errors for missing,
// unsupported, malformed and empty files.
#include "core/mesh_io.h"

#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A fresh folder under the system temp dir, removed at the end of the test.
using test_util::ReadBytes;
using test_util::TempDir;
using test_util::WriteText;

// A closed tetrahedron with shared vertices, one colour per face, off the origin.
TriangleMesh Tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0.1f, 0.2f, 0.3f,  //
      0.25f, 0.2f, 0.3f,              //
      0.1f, 0.33f, 0.3f,              //
      0.1f, 0.2f, 0.41f;
  mesh.faces.resize(4, 3);
  mesh.faces << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  mesh.face_colors.resize(4, 3);
  mesh.face_colors << 255, 0, 0, 0, 255, 0, 0, 0, 255, 12, 34, 56;
  return mesh;
}

// Expects the loaded mesh to have the same triangles, in order, as `expected` (the file's
// vertices are per face, so compare positions, not indices) and the same face colours.
void ExpectSameTriangles(const TriangleMesh& expected, const TriangleMesh& loaded,
                         double tolerance) {
  ASSERT_EQ(loaded.face_count(), expected.face_count());
  for (int f = 0; f < expected.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::RowVector3f a = expected.vertices.row(expected.faces(f, k));
      const Eigen::RowVector3f b = loaded.vertices.row(loaded.faces(f, k));
      EXPECT_LE((a - b).norm(), tolerance) << "face " << f << " corner " << k;
    }
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(loaded.face_colors(f, c), expected.face_colors(f, c)) << f;
  }
}

std::string LoadError(const fs::path& path, double scale = 1.0) {
  try {
    LoadMesh(path, scale);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "LoadMesh threw a non-InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "LoadMesh accepted " << path;
  return "";
}

TEST(MeshIoTest, PlyRoundTripKeepsTrianglesAndColours) {
  TempDir dir;
  const TriangleMesh mesh = Tetrahedron();
  WritePly(mesh, dir / "tet.ply");
  const TriangleMesh loaded = LoadMesh(dir / "tet.ply");
  ExpectSameTriangles(mesh, loaded, 0.0);  // floats written and read bit for bit
  EXPECT_NEAR(SignedVolume(loaded), SignedVolume(mesh), 1e-12);
  // Only the PLY and no temporary left behind.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "tet.ply");
  }
  EXPECT_EQ(files, 1);
}

TEST(MeshIoTest, PlyIsBinaryLittleEndianWithNormalsAndVertexColours) {
  TempDir dir;
  const TriangleMesh mesh = Tetrahedron();
  WritePly(mesh, dir / "tet.ply");
  const std::string bytes = ReadBytes(dir / "tet.ply");
  const auto end = bytes.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = bytes.substr(0, end);
  EXPECT_THAT(header, HasSubstr("format binary_little_endian 1.0"));
  EXPECT_THAT(header, HasSubstr("element vertex 12\n"));
  EXPECT_THAT(header, HasSubstr("property float nx"));
  EXPECT_THAT(header, HasSubstr("property uchar red"));
  EXPECT_THAT(header, HasSubstr("element face 4\n"));
  EXPECT_THAT(header, HasSubstr("property list uchar int vertex_indices"));
  const size_t body = end + std::strlen("end_header\n");
  EXPECT_EQ(bytes.size(), body + 12 * (6 * 4 + 3) + 4 * (1 + 3 * 4));
  // First vertex: x = 0.1f little-endian, its normal = the first face's outward normal (0, 0, -1).
  float x, nz;
  std::memcpy(&x, bytes.data() + body, 4);
  std::memcpy(&nz, bytes.data() + body + 20, 4);
  EXPECT_EQ(x, 0.1f);
  EXPECT_NEAR(nz, -1.0f, 1e-6);
  EXPECT_EQ(static_cast<uint8_t>(bytes[body + 24]), 255);
}

TEST(MeshIoTest, ScaleConvertsUnitsBothWays) {
  TempDir dir;
  const TriangleMesh mesh = Tetrahedron();
  WritePly(mesh, dir / "mm.ply", 1000.0);  // a BOP model in millimetres
  const TriangleMesh in_mm = LoadMesh(dir / "mm.ply");
  EXPECT_NEAR(in_mm.vertices(0, 0), 100.0f, 1e-4);
  ExpectSameTriangles(mesh, LoadMesh(dir / "mm.ply", 0.001), 1e-7);
}

TEST(MeshIoTest, ObjWithMaterialTriangulatesAndTakesDiffuseColour) {
  TempDir dir;
  WriteText(dir / "quad.mtl", "newmtl brick\nKd 0.8 0.4 0.2\n");
  WriteText(dir / "quad.obj",
            "# a unit square as one quad, and a triangle\n"
            "mtllib quad.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n"
            "usemtl brick\n"
            "f 1 2 3 4\n"
            "f 1 2 5\n");
  const TriangleMesh mesh = LoadMesh(dir / "quad.obj", 0.5);
  ASSERT_EQ(mesh.face_count(), 3);
  EXPECT_NEAR(SurfaceArea(mesh), 0.25 + 0.125, 1e-7);
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(mesh.face_colors(f, 0), 204);
    EXPECT_EQ(mesh.face_colors(f, 1), 102);
    EXPECT_EQ(mesh.face_colors(f, 2), 51);
  }
  EXPECT_NEAR(ComputeBounds(mesh).max.z(), 0.5, 1e-7);
}

TEST(MeshIoTest, ObjWithoutMaterialIsDefaultGrey) {
  TempDir dir;
  WriteText(dir / "tri.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");  // extension in capitals
  const TriangleMesh mesh = LoadMesh(dir / "tri.OBJ");
  ASSERT_EQ(mesh.face_count(), 1);
  EXPECT_EQ(mesh.face_colors(0, 0), kDefaultMeshColor[0]);
  EXPECT_EQ(mesh.face_colors(0, 2), kDefaultMeshColor[2]);
  EXPECT_NEAR(FaceNormals(mesh)(0, 2), 1.0f, 1e-6);  // winding kept
}

TEST(MeshIoTest, AsciiPlyVertexColoursAreAveragedPerFace) {
  TempDir dir;
  WriteText(dir / "rgb.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\n"
            "property float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n");
  const TriangleMesh mesh = LoadMesh(dir / "rgb.ply");
  ASSERT_EQ(mesh.face_count(), 1);
  EXPECT_EQ(mesh.face_colors(0, 0), 85);
  EXPECT_EQ(mesh.face_colors(0, 1), 85);
  EXPECT_EQ(mesh.face_colors(0, 2), 85);
}

TEST(MeshIoTest, MissingFileAndUnsupportedExtension) {
  TempDir dir;
  const std::string missing = LoadError(dir / "nothing.ply");
  EXPECT_THAT(missing, HasSubstr("nothing.ply"));
  EXPECT_THAT(missing, HasSubstr("missing file"));
  WriteText(dir / "model.stl", "solid x\nendsolid x\n");
  const std::string stl = LoadError(dir / "model.stl");
  EXPECT_THAT(stl, HasSubstr("model.stl"));
  EXPECT_THAT(stl, HasSubstr("'.stl'"));
  EXPECT_THAT(stl, HasSubstr(".obj or .ply"));
  EXPECT_THAT(LoadError(dir.path()), HasSubstr("extension"));
}

TEST(MeshIoTest, BrokenAndEmptyFilesAreInputErrors) {
  TempDir dir;
  WriteText(dir / "empty.ply", "");
  EXPECT_THAT(LoadError(dir / "empty.ply"), HasSubstr("empty.ply"));
  WriteText(dir / "garbage.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
            "property float x\nend_header\n\x01\x02");
  EXPECT_THAT(LoadError(dir / "garbage.ply"), HasSubstr("garbage.ply"));
  WriteText(dir / "empty.obj", "");
  EXPECT_THAT(LoadError(dir / "empty.obj"), HasSubstr("empty.obj"));
  WriteText(dir / "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_THAT(LoadError(dir / "points.obj"), HasSubstr("points.obj"));
  WriteText(dir / "lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
  EXPECT_THAT(LoadError(dir / "lines.obj"), HasSubstr("lines.obj"));
  WriteText(dir / "nofaces.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 0\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_THAT(LoadError(dir / "nofaces.ply"), HasSubstr("nofaces.ply"));
  // assimp 5 looped for ever on this one (a fuzz finding).
  WriteText(dir / "no_end_header.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int verader\n0 0 0\n1 0 0\n"
            "0 1 0\n3 0 1 2\n");
  EXPECT_THAT(LoadError(dir / "no_end_header.ply"),
              HasSubstr("no_end_header.ply:9: got '0 0 0', expected a PLY header line"));
  WriteText(dir / "cut_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
  EXPECT_THAT(LoadError(dir / "cut_header.ply"),
              HasSubstr("cut_header.ply: got a PLY header without an end_header line"));
}

TEST(MeshIoTest, NonFiniteVertexIsAnInputError) {
  TempDir dir;
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
      "property float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float coords[9] = {0, 0, 0, 1, std::numeric_limits<float>::quiet_NaN(), 0, 0, 1, 0};
  ply.append(reinterpret_cast<const char*>(coords), sizeof coords);
  const int32_t face[3] = {0, 1, 2};
  ply.push_back(3);
  ply.append(reinterpret_cast<const char*>(face), sizeof face);
  WriteText(dir / "nan.ply", ply);
  const std::string error = LoadError(dir / "nan.ply");
  EXPECT_THAT(error, HasSubstr("nan.ply"));
  EXPECT_THAT(error, HasSubstr("vertex 1"));
  EXPECT_THAT(error, HasSubstr("finite"));
}

TEST(MeshIoTest, BadScaleAndUnwritablePathAndInvalidMesh) {
  TempDir dir;
  WritePly(Tetrahedron(), dir / "tet.ply");
  EXPECT_THAT(LoadError(dir / "tet.ply", 0.0), HasSubstr("scale"));
  EXPECT_THROW(WritePly(Tetrahedron(), dir / "no_such_folder" / "tet.ply"), InputError);
  EXPECT_THROW(WritePly(Tetrahedron(), dir / "x.ply", -1.0), InputError);
  TriangleMesh empty;
  try {
    WritePly(empty, dir / "empty.ply");
    FAIL() << "an empty mesh was written";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("empty.ply"));
  }
  EXPECT_FALSE(fs::exists(dir / "empty.ply"));
}

// Appends `value` as its `sizeof(T)` bytes in big-endian order.
template <typename T>
void PutBigEndian(T value, std::string* out) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  for (int i = static_cast<int>(sizeof(T)) - 1; i >= 0; --i) out->push_back(static_cast<char>(raw[i]));
}

// The Stanford scans' layout (comments, extra per-vertex properties), with CRLF line ends and a
// quad: vertices as written, the quad split into two triangles (0 1 2) (0 2 3).
constexpr const char* kBunnyStylePly =
    "ply\r\nformat ascii 1.0\r\ncomment zipper output\r\nelement vertex 5\r\n"
    "property float x\r\nproperty float y\r\nproperty float z\r\n"
    "property float confidence\r\nproperty float intensity\r\n"
    "element face 2\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
    "0 0 0 0.85 0.5 \r\n1 0 0 0.9 0.5 \r\n1 1 0 0.4 0.5 \r\n0 1 0 0.85 0.5 \r\n"
    "0.5 0.5 1 1 1 \r\n4 0 1 2 3 \r\n3 0 1 4\r\n";

TEST(MeshIoReaderTest, AsciiPlyWithExtraPropertiesCrlfAndQuad) {
  TempDir dir;
  WriteText(dir / "bunny.ply", kBunnyStylePly);
  const TriangleMesh mesh = LoadMesh(dir / "bunny.ply");
  ASSERT_EQ(mesh.vertex_count(), 5);
  ASSERT_EQ(mesh.face_count(), 3);
  EXPECT_EQ(mesh.vertices(4, 0), 0.5f);
  EXPECT_EQ(mesh.vertices(4, 2), 1.0f);
  const std::vector<std::array<uint32_t, 3>> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
  for (int f = 0; f < 3; ++f) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.faces(f, k), expected[f][k]) << f;
    EXPECT_EQ(mesh.face_colors(f, 0), kDefaultMeshColor[0]);
  }
  EXPECT_NEAR(SurfaceArea(mesh), 1.0 + 0.5 * std::sqrt(1.25), 1e-6);
}

// A big-endian PLY of the kinds of property real files mix: double coordinates, normals, ushort
// colours, a uchar alpha, an int8 list count with uint indices, a face property after the list
// and an element the reader does not use (edges), in between.
std::string BigEndianPly() {
  std::string ply =
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 3\n"
      "property double x\nproperty double y\nproperty double z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property ushort red\nproperty ushort green\nproperty ushort blue\nproperty uchar alpha\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
      "element face 1\nproperty list int8 uint32 vertex_indices\nproperty uchar flags\n"
      "end_header\n";
  const double xyz[3][3] = {{0.125, -2, 3}, {1, 0, 0.5}, {0, 1e-3, 0}};
  const uint16_t rgb[3][3] = {{65535, 0, 0}, {0, 65535, 0}, {0, 0, 65535}};
  for (int v = 0; v < 3; ++v) {
    for (double c : xyz[v]) PutBigEndian(c, &ply);
    for (float n : {0.0f, 0.0f, 1.0f}) PutBigEndian(n, &ply);
    for (uint16_t c : rgb[v]) PutBigEndian(c, &ply);
    ply.push_back('\xff');
  }
  PutBigEndian<int32_t>(0, &ply);
  PutBigEndian<int32_t>(1, &ply);
  ply.push_back(3);
  for (uint32_t i : {2u, 0u, 1u}) PutBigEndian(i, &ply);
  ply.push_back(7);
  return ply;
}

TEST(MeshIoReaderTest, BigEndianPlyWithMixedTypesAndAnUnusedElement) {
  TempDir dir;
  WriteText(dir / "be.ply", BigEndianPly());
  const TriangleMesh mesh = LoadMesh(dir / "be.ply", 2.0);
  ASSERT_EQ(mesh.vertex_count(), 3);
  ASSERT_EQ(mesh.face_count(), 1);
  EXPECT_EQ(mesh.vertices(0, 0), 0.25f);
  EXPECT_EQ(mesh.vertices(0, 1), -4.0f);
  EXPECT_EQ(mesh.vertices(2, 1), 2e-3f);
  EXPECT_EQ(mesh.faces(0, 0), 2u);
  EXPECT_EQ(mesh.faces(0, 2), 1u);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(mesh.face_colors(0, c), 85);  // mean of 1, 0, 0
}

TEST(MeshIoReaderTest, ObjIndexFormsNegativeIndicesPolygonsAndVertexColours) {
  TempDir dir;
  WriteText(dir / "forms.obj",
            "# every corner form\r\no thing\ng part\ns 1\n"
            "v 0 0 0 1 0 0\nv 2 0 0 0 1 0\nv 2 2 0 0 0 1\nv 0 2 0 1 1 1\n"
            "v 0 0 4 2\n"  // w = 2: (0, 0, 2)
            "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n"
            "f 1/1/1 2/2/1 3/3/1\n"
            "f -4//-1 -2//1 -3//1\n"  // 2 4 3, counted back from vertex 5
            "l 1 2\np 1\n"
            "f 1/1 2/2 5/3 4/1 3/2\n");  // a pentagon: fan 1 2 5, 1 5 4, 1 4 3
  const TriangleMesh mesh = LoadMesh(dir / "forms.obj");
  ASSERT_EQ(mesh.vertex_count(), 5);
  ASSERT_EQ(mesh.face_count(), 5);
  EXPECT_EQ(mesh.vertices(4, 2), 2.0f);
  const std::vector<std::array<uint32_t, 3>> expected = {
      {0, 1, 2}, {1, 3, 2}, {0, 1, 4}, {0, 4, 3}, {0, 3, 2}};
  for (int f = 0; f < 5; ++f) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.faces(f, k), expected[f][k]) << f;
  }
  // Red, green, blue corners: 85 each; vertex 5 has no colour: the default.
  for (int c = 0; c < 3; ++c) EXPECT_EQ(mesh.face_colors(0, c), 85);
  EXPECT_EQ(mesh.face_colors(2, 0), kDefaultMeshColor[0]);
  // Red, white, blue: (2/3, 1/3, 2/3).
  EXPECT_EQ(mesh.face_colors(4, 0), 170);
  EXPECT_EQ(mesh.face_colors(4, 1), 85);
}

TEST(MeshIoReaderTest, ObjMaterialsGreyKdUnknownAndMissingLibraries) {
  TempDir dir;
  WriteText(dir / "my materials.mtl",
            "# two\nnewmtl grey one\nKa 1 1 1\nKd 0.5\nnewmtl red\nKd 1 0 0\nillum 2\n");
  WriteText(dir / "m.obj",
            "mtllib my materials.mtl\nmtllib missing.mtl\n"
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
            "f 1 2 3\nusemtl grey one\nf 1 2 3\nusemtl red\nf 1 2 3\nusemtl nowhere\nf 1 2 3\n");
  const TriangleMesh mesh = LoadMesh(dir / "m.obj");
  ASSERT_EQ(mesh.face_count(), 4);
  EXPECT_EQ(mesh.face_colors(0, 0), kDefaultMeshColor[0]);
  EXPECT_EQ(mesh.face_colors(1, 0), 128);
  EXPECT_EQ(mesh.face_colors(1, 2), 128);
  EXPECT_EQ(mesh.face_colors(2, 0), 255);
  EXPECT_EQ(mesh.face_colors(2, 1), 0);
  EXPECT_EQ(mesh.face_colors(3, 0), kDefaultMeshColor[0]);
}

// Malformed files: each an InputError whose message holds every expected part.
struct BadMesh {
  std::string name;  // the file name (its extension chooses the reader)
  std::string content;
  std::vector<std::string> expect;
};

const std::string kPlyHeader3 =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

std::vector<BadMesh> BadMeshes() {
  std::string truncated_binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  truncated_binary += std::string(3 * 12, '\0');
  truncated_binary += std::string("\x03\x00", 2);  // a face cut after its first index's byte
  return {
      // The fuzz finding (fuzz/regressions/mesh/assimp_triangulate_abort): assimp 5 aborted.
      {"abort.ply", kPlyHeader3.substr(0, kPlyHeader3.size() - 11) + "end_h\nend_header\n"
                        "0 0 0i 1.001 0 i1 2\n",
       {"abort.ply:9", "'end_h'", "a PLY header line"}},
      {"items.ply", kPlyHeader3 + "0 0 0i 1.001 0 i1 2\n",
       {"items.ply:10: vertex 0", "'0i' for property 'z'", "a number of type float"}},
      {"first.ply", "PLY\nformat ascii 1.0\nend_header\n", {"first.ply:1", "'PLY'", "'ply'"}},
      {"format.ply", "ply\nformat ascii 2.0\nend_header\n", {"format.ply:2", "format ascii 1.0"}},
      {"noformat.ply", "ply\nelement vertex 0\nend_header\n", {"noformat.ply:3", "format line"}},
      {"type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float64x x\nend_header\n",
       {"type.ply:4", "'float64x'", "uchar"}},
      {"nolist.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list float int v\nend_header\n",
       {"nolist.ply:4", "list count type 'float'", "integer"}},
      {"noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n",
       {"noxyz.ply:3", "property 'y'", "x, y and z"}},
      {"orphan.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
       {"orphan.ply:3", "after its element"}},
      {"count.ply", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n",
       {"count.ply:3", "'element vertex -3'", "count >= 0"}},
      {"huge.ply", kPlyHeader3.substr(0, 36) + "1000000000000000000" +
                       kPlyHeader3.substr(kPlyHeader3.find("\nproperty float x")) + "0 0 0\n",
       {"huge.ply:3", "1000000000000000000 items", "bytes after the header"}},
      {"short.ply", kPlyHeader3 + "0 0 0\n1 0 0\n", {"short.ply:11: vertex 2", "end of the file"}},
      {"long.ply", kPlyHeader3 + "0 0 0 7\n", {"long.ply:10: vertex 0", "'0 0 0 7'", "3 values"}},
      {"index.ply", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
       {"index.ply:13: face 0", "vertex index 3", "from 0 to 2"}},
      {"negative.ply", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
       {"negative.ply:13: face 0", "vertex index -1"}},
      {"listcount.ply", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n",
       {"listcount.ply:13: face 0", "'300'", "an integer of type uchar"}},
      {"extra.ply", kPlyHeader3 + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4 5 6\n",
       {"extra.ply:14", "after the last element"}},
      {"binary.ply", truncated_binary, {"binary.ply: face 0 (byte", "end of the file", "4 more bytes"}},
      {"infinite.ply", kPlyHeader3 + "0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n",
       {"infinite.ply: vertex 1", "finite"}},
      {"twice.ply", "ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\nend_header\n",
       {"twice.ply:4", "a second element 'vertex'"}},
      {"twiceprop.ply",
       "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float x\nend_header\n",
       {"twiceprop.ply:5", "a second property 'x'"}},
      {"obj_number.obj", "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n",
       {"obj_number.obj:2: v", "'x'", "a finite number"}},
      {"obj_count.obj", "v 0 0\n", {"obj_count.obj:1: v", "2 values", "'v x y z'"}},
      {"obj_nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", {"obj_nan.obj:2", "'nan'"}},
      {"obj_w.obj", "v 0 0 0 0\n", {"obj_w.obj:1: v", "w = 0"}},
      {"obj_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
       {"obj_zero.obj:4: f, corner 1", "vertex index '0'", "from 1 to 3 or from -3 to -1"}},
      {"obj_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
       {"obj_range.obj:4: f, corner 3", "'-4'"}},
      {"obj_before.obj", "f 1 2 3\nv 0 0 0\n", {"obj_before.obj:1", "a vertex defined before it"}},
      {"obj_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
       {"obj_vt.obj:5: f, corner 2", "texture coordinate index '2'", "from 1 to 1"}},
      {"obj_vn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n",
       {"obj_vn.obj:4: f, corner 1", "normal index '1'"}},
      {"obj_slashes.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n",
       {"obj_slashes.obj:4: f, corner 1", "'1/1/1/1'", "'v/vt/vn'"}},
      {"obj_junk.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2x 3\n", {"obj_junk.obj:4", "'2x'"}},
      {"obj_two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n",
       {"obj_two.obj:3: f", "2 corners", "at least 3"}},
      {"obj_statement.obj", "v 0 0 0\n0i 1.001\n", {"obj_statement.obj:2", "'0i'", "OBJ statement"}},
      {"obj_binary.obj", std::string("v 0 0 0\n\0\1\2", 11), {"obj_binary.obj"}},
      {"obj_kd.obj", "mtllib kd.mtl\nv 0 0 0\n", {"kd.mtl:2: Kd", "'red'"}},
  };
}

TEST(MeshIoReaderTest, MalformedFilesNameTheLineTheValueAndTheExpectation) {
  TempDir dir;
  WriteText(dir / "kd.mtl", "newmtl a\nKd red 0 0\n");
  for (const BadMesh& bad : BadMeshes()) {
    WriteText(dir / bad.name, bad.content);
    std::string message;
    try {
      LoadMesh(dir / bad.name);
      ADD_FAILURE() << bad.name << " was accepted";
      continue;
    } catch (const InputError& e) {
      message = e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << bad.name << ": not an InputError: " << e.what();
      continue;
    }
    for (const std::string& part : bad.expect) {
      EXPECT_THAT(message, HasSubstr(part)) << bad.name;
    }
    EXPECT_LT(message.size(), 400u) << message;
  }
}

// Triangles as assimp reads them: (corner positions, colour) per triangle, sorted, so that the
// two readers' orders (assimp groups an OBJ's faces by material) do not matter.
using Triangle = std::array<float, 12>;

std::vector<Triangle> Triangles(const TriangleMesh& mesh) {
  std::vector<Triangle> triangles;
  for (int f = 0; f < mesh.face_count(); ++f) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) t[3 * k + c] = mesh.vertices(mesh.faces(f, k), c);
    }
    for (int c = 0; c < 3; ++c) t[9 + c] = mesh.face_colors(f, c);
    triangles.push_back(t);
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

std::vector<Triangle> AssimpTriangles(const fs::path& path) {
  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_PreTransformVertices);
  EXPECT_NE(scene, nullptr) << path << ": " << importer.GetErrorString();
  std::vector<Triangle> triangles;
  if (scene == nullptr) return triangles;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    Rgb8 material = kDefaultMeshColor;
    aiColor4D diffuse;
    aiString name;
    const aiMaterial* mat = scene->mMaterials[part.mMaterialIndex];
    if (mat->Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS &&
        std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) != 0 &&
        mat->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == aiReturn_SUCCESS) {
      material = {static_cast<uint8_t>(std::lround(diffuse.r * 255)),
                  static_cast<uint8_t>(std::lround(diffuse.g * 255)),
                  static_cast<uint8_t>(std::lround(diffuse.b * 255))};
    }
    for (unsigned i = 0; i < part.mNumFaces; ++i) {
      const aiFace& face = part.mFaces[i];
      if (face.mNumIndices != 3) continue;
      Triangle t;
      float sum[3] = {0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        t[3 * k] = part.mVertices[v].x;
        t[3 * k + 1] = part.mVertices[v].y;
        t[3 * k + 2] = part.mVertices[v].z;
        if (part.mColors[0] != nullptr) {
          sum[0] += part.mColors[0][v].r;
          sum[1] += part.mColors[0][v].g;
          sum[2] += part.mColors[0][v].b;
        }
      }
      for (int c = 0; c < 3; ++c) {
        t[9 + c] = part.mColors[0] != nullptr
                       ? static_cast<float>(std::lround(std::clamp(sum[c] / 3, 0.0f, 1.0f) * 255))
                       : material[c];
      }
      triangles.push_back(t);
    }
  }
  std::sort(triangles.begin(), triangles.end());
  return triangles;
}

double Area(const std::vector<Triangle>& triangles) {
  double area = 0;
  for (const Triangle& t : triangles) {
    const Eigen::Vector3d a(t[0], t[1], t[2]), b(t[3], t[4], t[5]), c(t[6], t[7], t[8]);
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

// Same triangles and colours as assimp reads. A quad may be split along the other diagonal
// (`polygons`): then the triangle count, the area and the colours are compared.
void ExpectSameAsAssimp(const fs::path& path, bool polygons = false) {
  SCOPED_TRACE(path.string());
  const std::vector<Triangle> ours = Triangles(LoadMesh(path));
  const std::vector<Triangle> theirs = AssimpTriangles(path);
  ASSERT_EQ(ours.size(), theirs.size());
  ASSERT_FALSE(ours.empty());
  EXPECT_NEAR(Area(ours), Area(theirs), 1e-6 * Area(theirs));
  for (std::size_t t = 0; t < ours.size(); ++t) {
    for (int i = 0; i < 9 && !polygons; ++i) EXPECT_EQ(ours[t][i], theirs[t][i]) << "triangle " << t;
    for (int i = 9; i < 12; ++i) EXPECT_NEAR(ours[t][i], theirs[t][i], 1.0) << "triangle " << t;
  }
}

TEST(MeshIoReaderTest, SameTrianglesAsAssimpOnCommittedAndWrittenModels) {
  const fs::path source = MMH_SOURCE_DIR;
  // The committed models: YCB-Video's cuboids (tests/data/real).
  for (const char* model : {"tests/data/real/ycbv/models/009_gelatin_box.obj",
                            "tests/data/real/ycbv/models/061_foam_brick.obj"}) {
    ExpectSameAsAssimp(source / model);
  }
  TempDir dir;
  WritePly(Tetrahedron(), dir / "written.ply", 1000.0);  // what mmh writes for BOP
  ExpectSameAsAssimp(dir / "written.ply");
  WriteText(dir / "bunny.ply", kBunnyStylePly);
  ExpectSameAsAssimp(dir / "bunny.ply", /*polygons=*/true);  // assimp splits its quad 1-3
  WriteText(dir / "be.ply", BigEndianPly());
  ExpectSameAsAssimp(dir / "be.ply");
  WriteText(dir / "rgb.obj",
            "v 0 0 0 1 0 0\nv 2 0 0 0 1 0\nv 2 2 0 0 0 1\nv 0 2 0 1 1 1\nvn 0 0 1\n"
            "f 1//1 2//1 3//1\nf -4 -2 -1\nf 1 2 3 4\n");
  ExpectSameAsAssimp(dir / "rgb.obj");
  WriteText(dir / "quad.mtl", "newmtl brick\nKd 0.8 0.4 0.2\nnewmtl sky\nKd 0.1 0.5 0.9\n");
  WriteText(dir / "quad.obj",
            "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nvt 0 0\n"
            "usemtl brick\nf 1/1 2/1 3/1 4/1\nusemtl sky\nf 1 2 5\nf 2 3 5\n");
  ExpectSameAsAssimp(dir / "quad.obj");
}

}  // namespace
}  // namespace mmh
