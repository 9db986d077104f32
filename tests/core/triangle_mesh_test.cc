// Tests of core/triangle_mesh.h: appending, normals, bounds, validation, volume, closedness.
#include "core/triangle_mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/error.h"
#include "tests/test_meshes.h"

namespace mmh {
namespace {

using ::testing::HasSubstr;

// An axis-aligned box [0, sx] x [0, sy] x [0, sz] with shared vertices and outward faces, built by
// hand (the builders live in sim/ and are tested there).
// A box from the origin to (sx, sy, sz).
TriangleMesh Box(double sx, double sy, double sz, Rgb8 color = {10, 20, 30}) {
  return test_util::BoxMesh(Eigen::Vector3d::Zero(), Eigen::Vector3d(sx, sy, sz), color);
}

TEST(MeshTest, BoxHelperIsClosedWithOutwardNormals) {
  const TriangleMesh box = Box(0.2, 0.3, 0.5);
  EXPECT_TRUE(IsClosed(box));
  EXPECT_NEAR(SignedVolume(box), 0.2 * 0.3 * 0.5, 1e-6 * 0.03);  // float vertices
  EXPECT_NEAR(SurfaceArea(box), 2 * (0.2 * 0.3 + 0.2 * 0.5 + 0.3 * 0.5), 1e-6);
  const auto normals = FaceNormals(box);
  const Eigen::Vector3d centre(0.1, 0.15, 0.25);
  for (int f = 0; f < box.face_count(); ++f) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) centroid += box.vertices.row(box.faces(f, k)).cast<double>();
    centroid /= 3;
    EXPECT_NEAR(normals.row(f).norm(), 1.0, 1e-6);
    EXPECT_GT(normals.row(f).cast<double>().dot((centroid - centre).transpose()), 0) << f;
  }
}

TEST(MeshTest, FlippedOrMissingFacesAreNotClosed) {
  TriangleMesh flipped = Box(1, 1, 1);
  std::swap(flipped.faces(3, 1), flipped.faces(3, 2));
  EXPECT_FALSE(IsClosed(flipped));
  TriangleMesh open = Box(1, 1, 1);
  open.faces.conservativeResize(11, Eigen::NoChange);
  open.face_colors.conservativeResize(11, Eigen::NoChange);
  EXPECT_FALSE(IsClosed(open));
  EXPECT_FALSE(IsClosed(TriangleMesh{}));
  // Every face inverted: closed, but inside out.
  TriangleMesh inverted = Box(1, 2, 3);
  for (int f = 0; f < inverted.face_count(); ++f)
    std::swap(inverted.faces(f, 1), inverted.faces(f, 2));
  EXPECT_TRUE(IsClosed(inverted));
  EXPECT_NEAR(SignedVolume(inverted), -6.0, 1e-9);
}

TEST(MeshTest, SignedVolumeIsTranslationInvariantAndAdditive) {
  TriangleMesh two;
  AppendMesh(Box(0.1, 0.1, 0.1), Rigid3::Identity(), &two);
  const Rigid3 far(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(100.0, -50.0, 20.0));
  AppendMesh(Box(0.2, 0.1, 0.1), far, &two);
  EXPECT_TRUE(IsClosed(two));
  EXPECT_NEAR(SignedVolume(two), 0.001 + 0.002, 1e-7);
}

TEST(MeshTest, AppendMeshOffsetsIndicesMapsVerticesAndKeepsColours) {
  TriangleMesh mesh = Box(1, 1, 1, {1, 2, 3});
  const Rigid3 mesh_T_part(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ())),
      Eigen::Vector3d(10, 0, 0));
  AppendMesh(Box(2, 1, 1, {4, 5, 6}), mesh_T_part, &mesh);
  ASSERT_EQ(mesh.vertex_count(), 16);
  ASSERT_EQ(mesh.face_count(), 24);
  EXPECT_EQ(mesh.faces(12, 0), 8u);  // first face of the part: its vertex 0 moved to 8
  EXPECT_EQ(mesh.face_colors(11, 0), 1);
  EXPECT_EQ(mesh.face_colors(12, 0), 4);
  // Part vertex 1 = (2, 0, 0) rotated by 90 degrees about z and moved by (10, 0, 0).
  EXPECT_NEAR(mesh.vertices(9, 0), 10.0, 1e-6);
  EXPECT_NEAR(mesh.vertices(9, 1), 2.0, 1e-6);
  EXPECT_NO_THROW(ValidateMesh(mesh, "appended"));
  const Bounds3 bounds = ComputeBounds(mesh);
  EXPECT_NEAR(bounds.min.x(), 0.0, 1e-6);
  EXPECT_NEAR(bounds.max.x(), 10.0, 1e-6);
  EXPECT_NEAR(bounds.max.y(), 2.0, 1e-6);
  EXPECT_NEAR(bounds.max.z(), 1.0, 1e-6);
}

TEST(MeshTest, AppendMeshRejectsAPartWithoutColours) {
  TriangleMesh part = Box(1, 1, 1);
  part.face_colors.resize(0, 3);
  TriangleMesh mesh;
  EXPECT_THROW(AppendMesh(part, Rigid3::Identity(), &mesh), std::invalid_argument);
}

TEST(MeshTest, TransformedAndSetColor) {
  TriangleMesh box = Box(1, 1, 1);
  const TriangleMesh moved =
      Transformed(box, Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 5)));
  EXPECT_NEAR(ComputeBounds(moved).min.z(), 5.0, 1e-6);
  EXPECT_EQ(moved.faces, box.faces);
  SetColor(&box, {7, 8, 9});
  for (int f = 0; f < box.face_count(); ++f) {
    EXPECT_EQ(box.face_colors(f, 0), 7);
    EXPECT_EQ(box.face_colors(f, 2), 9);
  }
}

TEST(MeshTest, DegenerateFaceHasZeroNormal) {
  TriangleMesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 0, 0, 1, 1, 1, 2, 2, 2;  // collinear
  mesh.faces.resize(1, 3);
  mesh.faces << 0, 1, 2;
  SetColor(&mesh, kDefaultMeshColor);
  EXPECT_EQ(FaceNormals(mesh).row(0).norm(), 0.0f);
  EXPECT_DOUBLE_EQ(SurfaceArea(mesh), 0.0);
}

TEST(MeshTest, EmptyMeshHasEmptyBounds) {
  EXPECT_TRUE(ComputeBounds(TriangleMesh{}).empty());
  EXPECT_FALSE(ComputeBounds(Box(1, 1, 1)).empty());
}

void ExpectInvalid(const TriangleMesh& mesh, const std::string& fragment) {
  try {
    ValidateMesh(mesh, "proxy.obj");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("proxy.obj"));
    EXPECT_THAT(e.what(), HasSubstr(fragment));
  }
}

TEST(MeshTest, ValidateMeshNamesTheProblem) {
  ExpectInvalid(TriangleMesh{}, "no faces");
  TriangleMesh nan = Box(1, 1, 1);
  nan.vertices(5, 1) = std::numeric_limits<float>::quiet_NaN();
  ExpectInvalid(nan, "vertex 5");
  TriangleMesh index = Box(1, 1, 1);
  index.faces(7, 2) = 8;
  ExpectInvalid(index, "face 7");
  TriangleMesh colours = Box(1, 1, 1);
  colours.face_colors.conservativeResize(3, Eigen::NoChange);
  ExpectInvalid(colours, "3 face colours");
}

}  // namespace
}  // namespace mmh
