// Triangle meshes with per-face colour: proxy models (Duplo assemblies, loaded meshes), props and
// the hand. Shared by the simulator (which renders them) and the tracker (which gets the proxy's
// model from a file, never its pose).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

#include "core/rigid3.h"

namespace mmh {

// An 8-bit sRGB colour, channel order R, G, B.
using Rgb8 = std::array<std::uint8_t, 3>;

// The colour of a face when a file gives none (LoadMesh) [sRGB].
inline constexpr Rgb8 kDefaultMeshColor = {160, 160, 160};

struct TriangleMesh {
  // #V by 3 vertex positions [m] in the mesh's own frame.
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> vertices;
  // #F by 3 vertex indices, counter-clockwise seen from outside (outward normals by the right-hand
  // rule).
  Eigen::Matrix<uint32_t, Eigen::Dynamic, 3, Eigen::RowMajor> faces;
  // #F by 3 sRGB albedo per face.
  Eigen::Matrix<uint8_t, Eigen::Dynamic, 3, Eigen::RowMajor> face_colors;

  int vertex_count() const { return static_cast<int>(vertices.rows()); }
  int face_count() const { return static_cast<int>(faces.rows()); }
};

// Appends `part` (with its vertices mapped by mesh_T_part) to `mesh`.
void AppendMesh(const TriangleMesh& part, const Rigid3& mesh_T_part, TriangleMesh* mesh);

// #F by 3 unit outward face normals (zero for degenerate faces).
Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> FaceNormals(const TriangleMesh& mesh);

// Axis-aligned bounds of the vertices; min > max for an empty mesh.
struct Bounds3 {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-1e300);
  bool empty() const { return (min.array() > max.array()).any(); }
};
Bounds3 ComputeBounds(const TriangleMesh& mesh);

// Checks what a renderer and a tracker rely on: at least one face, finite vertices, indices in
// range, face_colors with one row per face. Throws InputError naming `where` and the first problem.
void ValidateMesh(const TriangleMesh& mesh, const std::string& where);

// The mesh with its vertices mapped by new_T_mesh (faces and colours unchanged).
TriangleMesh Transformed(const TriangleMesh& mesh, const Rigid3& new_T_mesh);

// Gives every face the colour `color`.
void SetColor(TriangleMesh* mesh, const Rgb8& color);

// Sum of the triangle areas [m^2].
double SurfaceArea(const TriangleMesh& mesh);

// Signed volume enclosed by the faces [m^3] (divergence theorem, sum of signed tetrahedra from the
// origin): the volume for a closed mesh with outward faces, minus it for inward faces. For a union
// of closed parts with disjoint interiors it is the sum of their volumes.
double SignedVolume(const TriangleMesh& mesh);

// True if every edge (by vertex index) is used once in each direction, that is by exactly two faces
// with consistent orientation: the mesh is a union of closed, oriented surfaces. Meshes whose
// vertices are duplicated per face (WritePly, most loaded files) are never closed by this test.
bool IsClosed(const TriangleMesh& mesh);

}  // namespace mmh
