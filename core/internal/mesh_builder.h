// What the PLY and OBJ readers of LoadMesh (core/mesh_io.h) share: a TriangleMesh grown vertex by
// vertex and polygon by polygon, with the face colour rule LoadMesh documents (the mean of the
// corners' vertex colours, else the polygon's material colour).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"

namespace mmh::internal {

// Most vertices or triangles a loaded mesh may have: TriangleMesh counts them in an int.
inline constexpr std::uint64_t kMaxMeshElements = (std::uint64_t{1} << 31) - 1;

// A colour channel in [0, 1] as an 8-bit value (clamped; NaN as 0).
std::uint8_t ColorByte(double value);

class MeshBuilder {
 public:
  // `where` (the file) prefixes the errors.
  explicit MeshBuilder(std::string where) : where_(std::move(where)) {}

  // Appends a vertex [file units]; `rgb` (channels in [0, 1]) when the file gives its colour.
  // More than kMaxMeshElements vertices is an InputError.
  void AddVertex(double x, double y, double z);
  void AddVertex(double x, double y, double z, const std::array<double, 3>& rgb);

  std::uint64_t vertex_count() const { return positions_.size() / 3; }

  // Appends the polygon with these vertex indices (each below vertex_count(), checked by the
  // reader) as a fan of triangles (corner 0, i, i + 1): the polygons of real models are convex.
  // Fewer than three corners adds nothing (points and lines are not part of a surface). Each
  // triangle's colour is the mean of its corners' vertex colours when all three have one, else
  // `material`.
  void AddPolygon(std::span<const std::uint32_t> corners, const Rgb8& material);

  // The mesh (vertices unscaled, as the file gives them).
  TriangleMesh Build() const;

 private:
  void CheckVertexCount() const;

  std::string where_;
  std::vector<float> positions_;     // 3 per vertex
  std::vector<float> colors_;        // 3 per vertex, when has_color_
  std::vector<bool> has_color_;      // per vertex
  std::vector<std::uint32_t> faces_;  // 3 per triangle
  std::vector<std::uint8_t> face_colors_;  // 3 per triangle
};

}  // namespace mmh::internal
