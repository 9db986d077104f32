// Meshes shared by the sensor tests.
#pragma once

#include "core/triangle_mesh.h"

namespace mmh::sim::test_meshes {

// A rectangle in the plane z = 0 of its own frame, normal +z, sx by sy metres.
inline TriangleMesh Quad(double sx, double sy) {
  TriangleMesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << -sx / 2, -sy / 2, 0, sx / 2, -sy / 2, 0, sx / 2, sy / 2, 0, -sx / 2, sy / 2, 0;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 0, 2, 3;
  mesh.face_colors.resize(2, 3);
  mesh.face_colors << 200, 180, 150, 200, 180, 150;
  return mesh;
}

}  // namespace mmh::sim::test_meshes
