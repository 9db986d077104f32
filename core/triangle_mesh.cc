#include "core/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "core/error.h"

namespace mmh {
namespace {

Eigen::Vector3d Vertex(const TriangleMesh& mesh, uint32_t index) {
  return mesh.vertices.row(index).transpose().cast<double>();
}

std::string FormatPoint(const Eigen::Vector3d& p) {
  return "(" + FormatNumber(p.x()) + ", " + FormatNumber(p.y()) + ", " + FormatNumber(p.z()) + ")";
}

}  // namespace

void AppendMesh(const TriangleMesh& part, const Rigid3& mesh_T_part, TriangleMesh* mesh) {
  if (part.face_colors.rows() != part.faces.rows()) {
    // A programming error (every builder sets one colour per face), not bad input.
    throw std::invalid_argument("AppendMesh: the part has " + std::to_string(part.faces.rows()) +
                                " faces but " + std::to_string(part.face_colors.rows()) +
                                " face colours");
  }
  const Eigen::Index v0 = mesh->vertices.rows();
  const Eigen::Index f0 = mesh->faces.rows();
  mesh->vertices.conservativeResize(v0 + part.vertices.rows(), Eigen::NoChange);
  mesh->faces.conservativeResize(f0 + part.faces.rows(), Eigen::NoChange);
  mesh->face_colors.conservativeResize(f0 + part.faces.rows(), Eigen::NoChange);
  for (Eigen::Index i = 0; i < part.vertices.rows(); ++i) {
    const Eigen::Vector3d p = mesh_T_part * part.vertices.row(i).transpose().cast<double>();
    mesh->vertices.row(v0 + i) = p.transpose().cast<float>();
  }
  const auto offset = static_cast<uint32_t>(v0);
  for (Eigen::Index f = 0; f < part.faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) mesh->faces(f0 + f, k) = part.faces(f, k) + offset;
  }
  mesh->face_colors.bottomRows(part.faces.rows()) = part.face_colors;
}

Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> FaceNormals(const TriangleMesh& mesh) {
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> normals(mesh.faces.rows(), 3);
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::Vector3d a = Vertex(mesh, mesh.faces(f, 0));
    const Eigen::Vector3d b = Vertex(mesh, mesh.faces(f, 1));
    const Eigen::Vector3d c = Vertex(mesh, mesh.faces(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double norm = n.norm();
    const Eigen::Vector3d unit = norm > 0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero();
    normals.row(f) = unit.transpose().cast<float>();
  }
  return normals;
}

Bounds3 ComputeBounds(const TriangleMesh& mesh) {
  Bounds3 bounds;
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Eigen::Vector3d p = mesh.vertices.row(i).transpose().cast<double>();
    bounds.min = bounds.min.cwiseMin(p);
    bounds.max = bounds.max.cwiseMax(p);
  }
  return bounds;
}

void ValidateMesh(const TriangleMesh& mesh, const std::string& where) {
  if (mesh.faces.rows() == 0) {
    ThrowBadValue(where, "a mesh with no faces", "at least one triangle");
  }
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    if (!mesh.vertices.row(i).allFinite()) {
      ThrowBadValue(where + ": vertex " + std::to_string(i),
                    FormatPoint(mesh.vertices.row(i).transpose().cast<double>()),
                    "finite coordinates");
    }
  }
  const auto vertex_count = static_cast<uint64_t>(mesh.vertices.rows());
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.faces(f, k) >= vertex_count) {
        ThrowBadValue(where + ": face " + std::to_string(f),
                      "vertex index " + std::to_string(mesh.faces(f, k)),
                      "indices below the vertex count " + std::to_string(vertex_count));
      }
    }
  }
  if (mesh.face_colors.rows() != mesh.faces.rows()) {
    ThrowBadValue(where, std::to_string(mesh.face_colors.rows()) + " face colours",
                  "one per face (" + std::to_string(mesh.faces.rows()) + ")");
  }
}

TriangleMesh Transformed(const TriangleMesh& mesh, const Rigid3& new_T_mesh) {
  TriangleMesh result = mesh;
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    result.vertices.row(i) =
        (new_T_mesh * mesh.vertices.row(i).transpose().cast<double>()).transpose().cast<float>();
  }
  return result;
}

void SetColor(TriangleMesh* mesh, const Rgb8& color) {
  mesh->face_colors.resize(mesh->faces.rows(), 3);
  for (Eigen::Index f = 0; f < mesh->faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) mesh->face_colors(f, k) = color[k];
  }
}

double SurfaceArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::Vector3d a = Vertex(mesh, mesh.faces(f, 0));
    area +=
        0.5 * (Vertex(mesh, mesh.faces(f, 1)) - a).cross(Vertex(mesh, mesh.faces(f, 2)) - a).norm();
  }
  return area;
}

double SignedVolume(const TriangleMesh& mesh) {
  // Tetrahedra from the first vertex rather than the origin: the same sum for a closed mesh, with
  // less cancellation for meshes far from their own origin.
  if (mesh.vertices.rows() == 0) return 0.0;
  const Eigen::Vector3d o = Vertex(mesh, 0);
  double six_volume = 0.0;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::Vector3d a = Vertex(mesh, mesh.faces(f, 0)) - o;
    const Eigen::Vector3d b = Vertex(mesh, mesh.faces(f, 1)) - o;
    const Eigen::Vector3d c = Vertex(mesh, mesh.faces(f, 2)) - o;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

bool IsClosed(const TriangleMesh& mesh) {
  if (mesh.faces.rows() == 0) return false;
  // Directed edge (from, to) -> number of uses; closed and oriented means each directed edge is
  // used once and its reverse once.
  std::unordered_map<uint64_t, int> uses;
  uses.reserve(static_cast<size_t>(mesh.faces.rows()) * 3);
  auto key = [](uint32_t from, uint32_t to) { return (uint64_t{from} << 32) | to; };
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t from = mesh.faces(f, k);
      const uint32_t to = mesh.faces(f, (k + 1) % 3);
      if (from == to) return false;
      if (++uses[key(from, to)] > 1) return false;
    }
  }
  for (const auto& [edge, count] : uses) {
    const auto reverse =
        key(static_cast<uint32_t>(edge & 0xffffffffu), static_cast<uint32_t>(edge >> 32));
    if (uses.find(reverse) == uses.end()) return false;
  }
  return true;
}

}  // namespace mmh
