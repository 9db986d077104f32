// Which pixels a moving object can cover: its triangles grouped into a few boxes, their
// projections' convex hulls scan-converted into row spans (the incremental renderer casts only
// those pixels against the object; docs/sensor.md, "Speed").
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/triangle_mesh.h"
#include "sim/ray_scene.h"

namespace mmh::sim::internal {

// The union of row intervals (overlapping or touching ones merged), ordered by row and column.
std::vector<PixelSpan> MergeRowIntervals(const std::vector<PixelSpan>& intervals);

// Boxes (object frame) bounding a mesh's triangles in up to 2^depth groups, split at the median
// along the longest axis of their centroids.
std::vector<Bounds3> ClusterBounds(const TriangleMesh& mesh, int depth);

// Adds to each image row v the columns u whose pixel centre (u, v) lies in a convex polygon
// (image coordinates, in order around it), widened by kCoverMargin px on every side: a camera
// ray meets what projects into the polygon only through such a centre. The margin covers the
// rounding of single-precision rays (about 1e-4 px here), with room to spare.
constexpr double kCoverMargin = 0.05;
void CoverConvexPolygon(const std::vector<Eigen::Vector2d>& polygon, int width, int height,
                        std::vector<PixelSpan>* rows);

// Convex hull of points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points);

}  // namespace mmh::sim::internal
