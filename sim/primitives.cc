#include "sim/primitives.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mmh::sim {
namespace {

// Builders reject impossible arguments as programming errors: the options that feed them are
// validated (with InputErrors naming the config key) before any mesh is built.
void Require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument(what);
}

void AddFace(TriangleMesh* mesh, Eigen::Index f, uint32_t a, uint32_t b, uint32_t c) {
  mesh->faces.row(f) << a, b, c;
}

}  // namespace

TriangleMesh MakeBox(const Eigen::Vector3d& size, const Rgb8& color) {
  Require(size.allFinite() && (size.array() > 0).all(), "MakeBox: sizes must be finite and > 0");
  return MakeBoxBetween(-0.5 * size, 0.5 * size, color);
}

TriangleMesh MakeBoxBetween(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                            const Rgb8& color) {
  Require(min.allFinite() && max.allFinite() && (max.array() > min.array()).all(),
          "MakeBoxBetween: corners must be finite with max > min");
  TriangleMesh mesh;
  mesh.vertices.resize(8, 3);
  // Vertex i + 2 j + 4 k is the corner with x = (min, max)[i], y = (min, max)[j], z = (min,
  // max)[k].
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        mesh.vertices.row(i + 2 * j + 4 * k) << static_cast<float>(i ? max.x() : min.x()),
            static_cast<float>(j ? max.y() : min.y()), static_cast<float>(k ? max.z() : min.z());
      }
    }
  }
  // Each side as a quad (a, b, c, d), counter-clockwise seen from outside.
  constexpr uint32_t kQuads[6][4] = {
      {0, 2, 3, 1},  // -z
      {4, 5, 7, 6},  // +z
      {0, 1, 5, 4},  // -y
      {2, 6, 7, 3},  // +y
      {0, 4, 6, 2},  // -x
      {1, 3, 7, 5},  // +x
  };
  mesh.faces.resize(12, 3);
  for (int q = 0; q < 6; ++q) {
    AddFace(&mesh, 2 * q, kQuads[q][0], kQuads[q][1], kQuads[q][2]);
    AddFace(&mesh, 2 * q + 1, kQuads[q][0], kQuads[q][2], kQuads[q][3]);
  }
  SetColor(&mesh, color);
  return mesh;
}

TriangleMesh MakeLathe(const std::vector<std::pair<double, double>>& profile, int segments,
                       const Rgb8& color) {
  const int points = static_cast<int>(profile.size());
  Require(segments >= 3, "MakeLathe: at least 3 segments");
  Require(points >= 3, "MakeLathe: a profile of at least 3 points (two poles and a ring)");
  Require(profile.front().first == 0 && profile.back().first == 0,
          "MakeLathe: the profile must start and end on the axis (radius 0)");
  for (int p = 0; p < points; ++p) {
    Require(std::isfinite(profile[p].first) && std::isfinite(profile[p].second),
            "MakeLathe: finite profile points");
    if (p > 0 && p < points - 1) Require(profile[p].first > 0, "MakeLathe: inner radii > 0");
  }
  const int rings = points - 2;
  TriangleMesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(rings) * segments + 2, 3);
  // Vertex 0: bottom pole; 1 + r * segments + i: ring r, angle i; last: top pole.
  const uint32_t bottom = 0;
  const auto top = static_cast<uint32_t>(rings * segments + 1);
  mesh.vertices.row(bottom) << 0.0f, 0.0f, static_cast<float>(profile.front().second);
  mesh.vertices.row(top) << 0.0f, 0.0f, static_cast<float>(profile.back().second);
  for (int r = 0; r < rings; ++r) {
    const auto [radius, z] = profile[r + 1];
    for (int i = 0; i < segments; ++i) {
      const double angle = 2.0 * std::numbers::pi * i / segments;
      mesh.vertices.row(1 + r * segments + i) << static_cast<float>(radius * std::cos(angle)),
          static_cast<float>(radius * std::sin(angle)), static_cast<float>(z);
    }
  }
  auto ring_vertex = [segments](int r, int i) {
    return static_cast<uint32_t>(1 + r * segments + (i % segments));
  };
  mesh.faces.resize(static_cast<Eigen::Index>(2) * segments * rings, 3);
  Eigen::Index f = 0;
  for (int i = 0; i < segments; ++i) {
    AddFace(&mesh, f++, bottom, ring_vertex(0, i + 1), ring_vertex(0, i));
  }
  for (int r = 0; r + 1 < rings; ++r) {
    for (int i = 0; i < segments; ++i) {
      const uint32_t a = ring_vertex(r, i);
      const uint32_t b = ring_vertex(r, i + 1);
      const uint32_t c = ring_vertex(r + 1, i + 1);
      const uint32_t d = ring_vertex(r + 1, i);
      AddFace(&mesh, f++, a, b, c);
      AddFace(&mesh, f++, a, c, d);
    }
  }
  for (int i = 0; i < segments; ++i) {
    AddFace(&mesh, f++, ring_vertex(rings - 1, i), ring_vertex(rings - 1, i + 1), top);
  }
  SetColor(&mesh, color);
  return mesh;
}

TriangleMesh MakeCylinder(double radius, double height, int segments, const Rgb8& color) {
  return MakeFrustum(radius, radius, height, segments, color);
}

TriangleMesh MakeFrustum(double r_bottom, double r_top, double height, int segments,
                         const Rgb8& color) {
  Require(std::isfinite(r_bottom) && std::isfinite(r_top) && r_bottom >= 0 && r_top >= 0 &&
              (r_bottom > 0 || r_top > 0),
          "MakeFrustum: radii finite, >= 0, not both 0");
  Require(std::isfinite(height) && height > 0, "MakeFrustum: height finite and > 0");
  std::vector<std::pair<double, double>> profile = {{0.0, 0.0}};
  if (r_bottom > 0) profile.emplace_back(r_bottom, 0.0);
  if (r_top > 0) profile.emplace_back(r_top, height);
  profile.emplace_back(0.0, height);
  return MakeLathe(profile, segments, color);
}

TriangleMesh MakeCone(double radius, double height, int segments, const Rgb8& color) {
  return MakeFrustum(radius, 0.0, height, segments, color);
}

TriangleMesh MakeSphere(double radius, int segments, const Rgb8& color) {
  Require(std::isfinite(radius) && radius > 0, "MakeSphere: radius finite and > 0");
  const int bands = std::max(2, segments / 2);
  std::vector<std::pair<double, double>> profile;
  for (int b = 0; b <= bands; ++b) {
    const double polar = std::numbers::pi * (1.0 - static_cast<double>(b) / bands);  // from -z
    const double r = (b == 0 || b == bands) ? 0.0 : radius * std::sin(polar);
    profile.emplace_back(r, radius * std::cos(polar));
  }
  return MakeLathe(profile, segments, color);
}

TriangleMesh MakeCapsule(double radius, double length, int segments, const Rgb8& color) {
  Require(std::isfinite(radius) && radius > 0, "MakeCapsule: radius finite and > 0");
  Require(std::isfinite(length) && length >= 0, "MakeCapsule: length finite and >= 0");
  const int rings = std::max(2, segments / 4);  // per hemisphere, the equator included
  std::vector<std::pair<double, double>> profile = {{0.0, -radius}};
  for (int k = 1; k <= rings; ++k) {  // bottom hemisphere, up to its equator at z = 0
    const double latitude = -0.5 * std::numbers::pi * (1.0 - static_cast<double>(k) / rings);
    profile.emplace_back(radius * std::cos(latitude), radius * std::sin(latitude));
  }
  const int first_top = length > 0 ? 0 : 1;  // a zero length shares the equator: a sphere
  for (int k = first_top; k < rings; ++k) {
    const double latitude = 0.5 * std::numbers::pi * static_cast<double>(k) / rings;
    profile.emplace_back(radius * std::cos(latitude), length + radius * std::sin(latitude));
  }
  profile.emplace_back(0.0, length + radius);
  return MakeLathe(profile, segments, color);
}

TriangleMesh MakeCapsuleBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                double radius, int segments, const Rgb8& color) {
  Require(from.allFinite() && to.allFinite(), "MakeCapsuleBetween: finite end points");
  const Eigen::Vector3d axis = to - from;
  const double length = axis.norm();
  Rigid3 world_T_capsule;
  world_T_capsule.translation = from;
  if (length > 0) {
    world_T_capsule.rotation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis);
  }
  return Transformed(MakeCapsule(radius, length, segments, color), world_T_capsule);
}

}  // namespace mmh::sim
