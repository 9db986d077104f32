#include "sim/internal/screen_cover.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace mmh::sim::internal {

// The union of row intervals (overlapping or touching ones merged), ordered by row and column.
// Rows are few (an image's height), so the intervals are bucketed by row (a counting sort) and
// only each row's handful is sorted by column.
std::vector<PixelSpan> MergeRowIntervals(const std::vector<PixelSpan>& intervals) {
  std::vector<PixelSpan> spans;
  if (intervals.empty()) return spans;
  int row_min = intervals.front().row, row_max = row_min;
  for (const PixelSpan& s : intervals) {
    row_min = std::min(row_min, s.row);
    row_max = std::max(row_max, s.row);
  }
  std::vector<int> start(static_cast<size_t>(row_max - row_min) + 2, 0);
  for (const PixelSpan& s : intervals) ++start[s.row - row_min + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<PixelSpan> by_row(intervals.size());
  std::vector<int> next(start.begin(), start.end() - 1);
  for (const PixelSpan& s : intervals) by_row[next[s.row - row_min]++] = s;
  for (size_t r = 0; r + 1 < start.size(); ++r) {
    const auto first = by_row.begin() + start[r], last = by_row.begin() + start[r + 1];
    std::sort(first, last,
              [](const PixelSpan& x, const PixelSpan& y) { return x.first < y.first; });
    const size_t row_begin = spans.size();
    for (auto it = first; it != last; ++it) {
      if (spans.size() > row_begin && it->first <= spans.back().last + 1) {
        spans.back().last = std::max(spans.back().last, it->last);
      } else {
        spans.push_back(*it);
      }
    }
  }
  return spans;
}

// Boxes (object frame) bounding a mesh's triangles in up to 2^depth groups, split at the median
// along the longest axis of their centroids: a moving object's screen coverage is the union of
// its boxes' projections, much tighter than one box for a bent arm.
std::vector<Bounds3> ClusterBounds(const TriangleMesh& mesh, int depth) {
  std::vector<int> faces(mesh.face_count());
  std::iota(faces.begin(), faces.end(), 0);
  auto centroid = [&](int f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += mesh.vertices.row(mesh.faces(f, k)).transpose().cast<double>();
    return Eigen::Vector3d(c / 3.0);
  };
  std::vector<Bounds3> boxes;
  auto split = [&](auto&& self, std::vector<int>::iterator first, std::vector<int>::iterator last,
                   int level) -> void {
    if (first == last) return;
    if (level == depth || last - first < 16) {
      Bounds3 box;
      for (auto it = first; it != last; ++it) {
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d p =
              mesh.vertices.row(mesh.faces(*it, k)).transpose().template cast<double>();
          box.min = box.min.cwiseMin(p);
          box.max = box.max.cwiseMax(p);
        }
      }
      boxes.push_back(box);
      return;
    }
    Bounds3 spread;
    for (auto it = first; it != last; ++it) {
      const Eigen::Vector3d c = centroid(*it);
      spread.min = spread.min.cwiseMin(c);
      spread.max = spread.max.cwiseMax(c);
    }
    int axis = 0;
    (spread.max - spread.min).maxCoeff(&axis);
    auto middle = first + (last - first) / 2;
    std::nth_element(first, middle, last,
                     [&](int a, int b) { return centroid(a)[axis] < centroid(b)[axis]; });
    self(self, first, middle, level + 1);
    self(self, middle, last, level + 1);
  };
  split(split, faces.begin(), faces.end(), 0);
  return boxes;
}

void CoverConvexPolygon(const std::vector<Eigen::Vector2d>& polygon, int width, int height,
                        std::vector<PixelSpan>* rows) {
  double y_min = 1e300, y_max = -1e300;
  for (const Eigen::Vector2d& p : polygon) {
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
  }
  const int v0 = std::max(0, static_cast<int>(std::ceil(y_min - kCoverMargin)));
  const int v1 = std::min(height - 1, static_cast<int>(std::floor(y_max + kCoverMargin)));
  if (v0 > v1) return;
  // Per row v the x extent of the polygon within the band [v - margin, v + margin]: each edge
  // contributes its x at the ends of its part inside the band (x linear in y along the edge; the
  // slope is computed once per edge, not once per row).
  const size_t n = polygon.size();
  std::vector<double> x_min(v1 - v0 + 1, 1e300), x_max(v1 - v0 + 1, -1e300);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % n];
    const double dy = b.y() - a.y();
    const double edge_y_min = std::min(a.y(), b.y()), edge_y_max = std::max(a.y(), b.y());
    const int first = std::max(v0, static_cast<int>(std::ceil(edge_y_min - kCoverMargin)));
    const int last = std::min(v1, static_cast<int>(std::floor(edge_y_max + kCoverMargin)));
    const double slope = dy == 0.0 ? 0.0 : (b.x() - a.x()) / dy;
    for (int v = first; v <= last; ++v) {
      double xa, xb;
      if (dy == 0.0) {
        xa = a.x();
        xb = b.x();
      } else {
        const double lo = std::max(edge_y_min, v - kCoverMargin);
        const double hi = std::min(edge_y_max, v + kCoverMargin);
        xa = a.x() + (lo - a.y()) * slope;
        xb = a.x() + (hi - a.y()) * slope;
      }
      double& row_min = x_min[v - v0];
      double& row_max = x_max[v - v0];
      row_min = std::min({row_min, xa, xb});
      row_max = std::max({row_max, xa, xb});
    }
  }
  for (int v = v0; v <= v1; ++v) {
    if (x_min[v - v0] > x_max[v - v0]) continue;
    const int u0 = std::max(0, static_cast<int>(std::ceil(x_min[v - v0] - kCoverMargin)));
    const int u1 = std::min(width - 1, static_cast<int>(std::floor(x_max[v - v0] + kCoverMargin)));
    if (u0 > u1) continue;
    rows->push_back({v, u0, u1});
  }
}

// Convex hull of points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> ConvexHull(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  size_t k = 0;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

}  // namespace mmh::sim::internal
