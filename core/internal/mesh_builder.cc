#include "core/internal/mesh_builder.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace mmh::internal {

std::uint8_t ColorByte(double value) {
  const double clamped = std::clamp(std::isnan(value) ? 0.0 : value, 0.0, 1.0);
  return static_cast<std::uint8_t>(std::lround(clamped * 255.0));
}

void MeshBuilder::CheckVertexCount() const {
  if (vertex_count() >= kMaxMeshElements) {
    ThrowBadValue(where_, "more than " + std::to_string(kMaxMeshElements) + " vertices",
                  "a mesh of fewer vertices");
  }
}

void MeshBuilder::AddVertex(double x, double y, double z) {
  CheckVertexCount();
  positions_.insert(positions_.end(),
                    {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)});
  colors_.insert(colors_.end(), {0.0f, 0.0f, 0.0f});
  has_color_.push_back(false);
}

void MeshBuilder::AddVertex(double x, double y, double z, const std::array<double, 3>& rgb) {
  AddVertex(x, y, z);
  std::copy(rgb.begin(), rgb.end(), colors_.end() - 3);
  has_color_.back() = true;
}

void MeshBuilder::AddPolygon(std::span<const std::uint32_t> corners, const Rgb8& material) {
  for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
    if (faces_.size() / 3 >= kMaxMeshElements) {
      ThrowBadValue(where_, "more than " + std::to_string(kMaxMeshElements) + " triangles",
                    "a mesh of fewer triangles");
    }
    const std::uint32_t triangle[3] = {corners[0], corners[i], corners[i + 1]};
    faces_.insert(faces_.end(), triangle, triangle + 3);
    const bool colored = std::all_of(triangle, triangle + 3,
                                     [&](std::uint32_t v) { return has_color_[v]; });
    for (int c = 0; c < 3; ++c) {
      if (!colored) {
        face_colors_.push_back(material[c]);
        continue;
      }
      double sum = 0;
      for (std::uint32_t v : triangle) sum += colors_[3 * v + c];
      face_colors_.push_back(ColorByte(sum / 3.0));
    }
  }
}

TriangleMesh MeshBuilder::Build() const {
  TriangleMesh mesh;
  const auto vertices = static_cast<Eigen::Index>(vertex_count());
  const auto faces = static_cast<Eigen::Index>(faces_.size() / 3);
  mesh.vertices.resize(vertices, 3);
  std::copy(positions_.begin(), positions_.end(), mesh.vertices.data());
  mesh.faces.resize(faces, 3);
  std::copy(faces_.begin(), faces_.end(), mesh.faces.data());
  mesh.face_colors.resize(faces, 3);
  std::copy(face_colors_.begin(), face_colors_.end(), mesh.face_colors.data());
  return mesh;
}

}  // namespace mmh::internal
