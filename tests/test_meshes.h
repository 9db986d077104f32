// Small meshes the test suites build by hand.
#pragma once

#include <Eigen/Core>

#include "core/triangle_mesh.h"

namespace mmh::test_util {

// The axis-aligned box from corner `lo` to corner `hi`: corner i at x = (i & 1 ? hi : lo).x(),
// y from i & 2, z from i & 4; 12 triangles with outward normals, one colour.
inline TriangleMesh BoxMesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                            const Rgb8& color = kDefaultMeshColor) {
  TriangleMesh mesh;
  mesh.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.row(i) << static_cast<float>(i & 1 ? hi.x() : lo.x()),
        static_cast<float>(i & 2 ? hi.y() : lo.y()), static_cast<float>(i & 4 ? hi.z() : lo.z());
  }
  mesh.faces.resize(12, 3);
  mesh.faces << 0, 2, 1, 1, 2, 3,  // z-
      4, 5, 6, 5, 7, 6,            // z+
      0, 1, 4, 1, 5, 4,            // y-
      2, 6, 3, 3, 6, 7,            // y+
      0, 4, 2, 2, 4, 6,            // x-
      1, 3, 5, 3, 7, 5;            // x+
  SetColor(&mesh, color);
  return mesh;
}

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

// A box of size (sx, sy, sz) centred on the origin.
inline TriangleMesh CentredBox(double sx, double sy, double sz,
                               const Rgb8& color = kDefaultMeshColor) {
  return BoxMesh(Eigen::Vector3d(-sx / 2, -sy / 2, -sz / 2), Eigen::Vector3d(sx / 2, sy / 2, sz / 2),
                 color);
}

}  // namespace mmh::test_util
