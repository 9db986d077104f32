// Mesh builders for the simulator's scene: boxes, solids of revolution, capsules. Metres, faces
// counter-clockwise seen from outside (outward normals), one colour per mesh. Every builder returns
// a closed surface (IsClosed), so its SignedVolume is its volume.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "core/triangle_mesh.h"

namespace mmh::sim {

// Box of size (x, y, z) [m] centred at the origin, axis-aligned: 8 vertices, 12 faces.
TriangleMesh MakeBox(const Eigen::Vector3d& size, const Rgb8& color);

// Axis-aligned box from corner `min` to corner `max` [m].
TriangleMesh MakeBoxBetween(const Eigen::Vector3d& min, const Eigen::Vector3d& max,
                            const Rgb8& color);

// Solid of revolution about the z axis: `profile` is a list of (radius, z) [m] from the bottom to
// the top of the outline; the first and last points must have radius 0 (they become the two poles,
// closing the surface), the others radius > 0. Each ring is a regular polygon of `segments` >= 3
// vertices, the first at angle 0 (on +x): 2 segments (points - 2) triangles.
TriangleMesh MakeLathe(const std::vector<std::pair<double, double>>& profile, int segments,
                       const Rgb8& color);

// Capped cylinder of `radius`, axis z from z = 0 to z = height [m]; its cross-section is a regular
// `segments`-gon inscribed in the circle, so its volume is segments/2 sin(2 pi/segments) r^2 h.
TriangleMesh MakeCylinder(double radius, double height, int segments, const Rgb8& color);

// Capped truncated cone, axis z, radius r_bottom at z = 0 and r_top at z = height [m]. Either
// radius may be 0 (a cone), not both.
TriangleMesh MakeFrustum(double r_bottom, double r_top, double height, int segments,
                         const Rgb8& color);

// Cone with its base (radius) at z = 0 and its apex at z = height [m].
TriangleMesh MakeCone(double radius, double height, int segments, const Rgb8& color);

// Sphere of `radius` centred at the origin: `segments` around the z axis, segments / 2 bands from
// pole to pole.
TriangleMesh MakeSphere(double radius, int segments, const Rgb8& color);

// Capsule (a finger's phalanx, a limb): the cylinder of `radius` around the segment from (0, 0, 0)
// to (0, 0, length) with a hemisphere on each end, so it spans z in [-radius, length + radius].
// `segments` around, max(2, segments / 4) rings per hemisphere.
TriangleMesh MakeCapsule(double radius, double length, int segments, const Rgb8& color);

// The same capsule around the segment from `from` to `to` (any direction) [m].
TriangleMesh MakeCapsuleBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                double radius, int segments, const Rgb8& color);

}  // namespace mmh::sim
