#include "track/proxy_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "core/error.h"

namespace mmh::track {

void ProxyModelOptions::Validate(const std::string& prefix) const {
  auto range = [&](double value, double lo, double hi, const char* name) {
    RequireFinite(value, prefix + "." + name);
    if (!(value >= lo && value <= hi)) {
      ThrowBadValue(prefix + "." + name, FormatNumber(value),
                    "a length in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "] m");
    }
  };
  range(sample_spacing, 0.0002, 0.02, "sample_spacing");
  range(grid_resolution, 0.0005, 0.02, "grid_resolution");
  range(grid_margin, 0.005, 0.2, "grid_margin");
  range(fine_distance, 0.0, 0.2, "fine_distance");
}

namespace {

// Surface samples of a mesh with their face normals and faces.
struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points, normals;
  std::vector<int> faces;
};

// Per face, a deterministic R2 low-discrepancy sequence (Roberts 2018) folded into the triangle,
// count proportional to the area (one sample per spacing^2, at least one per face with an area).
SurfaceSamples SampleSurface(const TriangleMesh& mesh, double spacing) {
  SurfaceSamples samples;
  const auto face_normals = FaceNormals(mesh);
  const double g = 1.32471795724474602596;  // plastic number
  const double a1 = 1.0 / g, a2 = 1.0 / (g * g);
  const double cell_area = spacing * spacing;
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Eigen::Vector3f n = face_normals.row(f).transpose();
    if (n.squaredNorm() == 0) continue;
    const Eigen::Vector3f a = mesh.vertices.row(mesh.faces(f, 0)).transpose();
    const Eigen::Vector3f b = mesh.vertices.row(mesh.faces(f, 1)).transpose();
    const Eigen::Vector3f c = mesh.vertices.row(mesh.faces(f, 2)).transpose();
    const double area = 0.5 * (b - a).cross(c - a).norm();
    const int count = std::max(1, static_cast<int>(std::lround(area / cell_area)));
    for (int i = 0; i < count; ++i) {
      double s = std::fmod(0.5 + a1 * (i + 1), 1.0), t = std::fmod(0.5 + a2 * (i + 1), 1.0);
      if (s + t > 1) {
        s = 1 - s;
        t = 1 - t;
      }
      samples.points.push_back(a + static_cast<float>(s) * (b - a) +
                               static_cast<float>(t) * (c - a));
      samples.normals.push_back(n);
      samples.faces.push_back(f);
    }
  }
  return samples;
}

// Sparse subset: one sample per 4 mm cell and normal direction (the dominant axis and its sign,
// so that both sides of a thin part keep samples).
std::vector<int> SparseSubset(const std::vector<Eigen::Vector3f>& points,
                              const std::vector<Eigen::Vector3f>& normals,
                              const Eigen::Vector3f& min_corner) {
  std::vector<int> sparse;
  const float inverse_cell = 1.0f / 0.004f;
  std::unordered_map<int64_t, int> seen;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector3f q = (points[i] - min_corner) * inverse_cell;
    int axis = 0;
    normals[i].cwiseAbs().maxCoeff(&axis);
    const int direction = 2 * axis + (normals[i][axis] > 0 ? 1 : 0);
    const int64_t key =
        ((static_cast<int64_t>(q.x()) * 4096 + static_cast<int64_t>(q.y())) * 4096 +
         static_cast<int64_t>(q.z())) *
            8 +
        direction;
    if (seen.emplace(key, i).second) sparse.push_back(i);
  }
  return sparse;
}

// A regular grid of cells: origin (the first cell's corner), cell size and cells per axis, cell
// (x, y, z) at index z * dims[0] * dims[1] + y * dims[0] + x.
struct GridShape {
  Eigen::Vector3f origin;
  float resolution = 1;
  const int* dims = nullptr;
  Eigen::Vector3f Center(int x, int y, int z) const {
    return Eigen::Vector3f(origin + resolution * Eigen::Vector3f(x + 0.5f, y + 0.5f, z + 0.5f));
  }
};

// Every cell centre's nearest sample (grid) and its squared distance (best).
struct NearestSamples {
  std::vector<int32_t> grid;
  std::vector<float> best;
};

// Each cell seeded with the nearest sample inside it.
void SeedCells(const std::vector<Eigen::Vector3f>& points, const GridShape& shape,
               NearestSamples* nearest) {
  const int* dims = shape.dims;
  const size_t sx = 1, sy = dims[0], sz = static_cast<size_t>(dims[0]) * dims[1];
  const float inverse_resolution = 1.0f / shape.resolution;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const Eigen::Vector3f g = (points[i] - shape.origin) * inverse_resolution;
    const int x = std::clamp(static_cast<int>(g.x()), 0, dims[0] - 1);
    const int y = std::clamp(static_cast<int>(g.y()), 0, dims[1] - 1);
    const int z = std::clamp(static_cast<int>(g.z()), 0, dims[2] - 1);
    const size_t c = z * sz + y * sy + x * sx;
    const float d = (points[i] - shape.Center(x, y, z)).squaredNorm();
    if (d < nearest->best[c]) {
      nearest->best[c] = d;
      nearest->grid[c] = i;
    }
  }
}

// One sweep of the grid in `direction` (+1 forward, -1 backward): each cell takes one of the 13
// neighbours already visited in this order when its sample is nearer to the cell's centre.
void SweepCells(const std::vector<Eigen::Vector3f>& points, const GridShape& shape, int direction,
                NearestSamples* nearest) {
  const int* dims = shape.dims;
  const size_t sx = 1, sy = dims[0], sz = static_cast<size_t>(dims[0]) * dims[1];
  std::vector<int32_t>& grid = nearest->grid;
  std::vector<float>& best = nearest->best;
  const int x0 = direction > 0 ? 0 : dims[0] - 1, x1 = direction > 0 ? dims[0] : -1;
  const int y0 = direction > 0 ? 0 : dims[1] - 1, y1 = direction > 0 ? dims[1] : -1;
  const int z0 = direction > 0 ? 0 : dims[2] - 1, z1 = direction > 0 ? dims[2] : -1;
  for (int z = z0; z != z1; z += direction) {
    for (int y = y0; y != y1; y += direction) {
      for (int x = x0; x != x1; x += direction) {
        const size_t c = z * sz + y * sy + x * sx;
        const Eigen::Vector3f center = shape.Center(x, y, z);
        for (int dz = -1; dz <= 0; ++dz) {
          for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
              const int nx = x + direction * dx, ny = y + direction * dy, nz = z + direction * dz;
              if (nx < 0 || ny < 0 || nz < 0 || nx >= dims[0] || ny >= dims[1] || nz >= dims[2]) {
                continue;
              }
              const int candidate = grid[nz * sz + ny * sy + nx * sx];
              if (candidate < 0 || candidate == grid[c]) continue;
              const float d = (points[candidate] - center).squaredNorm();
              if (d < best[c]) {
                best[c] = d;
                grid[c] = candidate;
              }
            }
          }
        }
      }
    }
  }
}

// Every cell centre's nearest sample by vector propagation (Danielsson 1980, "Euclidean distance
// mapping"): seed each cell with the nearest sample inside it, then sweep the grid forward and
// backward, each cell taking a neighbour's sample when that one is nearer to its centre. Two
// double sweeps; the result is the true nearest sample or one within a fraction of a cell of it
// (the ICP uses the sample's face plane, which such a neighbour shares).
NearestSamples NearestSampleGrid(const std::vector<Eigen::Vector3f>& points,
                                 const GridShape& shape, size_t cells) {
  NearestSamples nearest{std::vector<int32_t>(cells, -1),
                         std::vector<float>(cells, std::numeric_limits<float>::infinity())};
  SeedCells(points, shape, &nearest);
  for (int pass = 0; pass < 2; ++pass) {
    SweepCells(points, shape, +1, &nearest);
    SweepCells(points, shape, -1, &nearest);
  }
  return nearest;
}

}  // namespace

ProxyModel::ProxyModel(const TriangleMesh& mesh, const ProxyModelOptions& options,
                       const std::string& where)
    : options_(options) {
  options_.Validate("model");
  ValidateMesh(mesh, where);
  const Bounds3 bounds = ComputeBounds(mesh);
  const Eigen::Vector3d size = bounds.max - bounds.min;
  if (size.maxCoeff() > 1.0) {
    ThrowBadValue(where, "a model " + FormatNumber(size.maxCoeff()) + " m across",
                  "a hand-held proxy under 1 m (a model in millimetres needs a scale of 0.001)");
  }
  if (SurfaceArea(mesh) <= 0) ThrowBadValue(where, "a model without area", "triangles with area");
  SurfaceSamples samples = SampleSurface(mesh, options_.sample_spacing);
  points_ = std::move(samples.points);
  normals_ = std::move(samples.normals);
  sample_faces_ = std::move(samples.faces);
  center_ = (0.5 * (bounds.min + bounds.max)).cast<float>();
  radius_ = static_cast<float>(0.5 * size.norm());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : points_) sum += p.cast<double>();
  centroid_ = (sum / static_cast<double>(points_.size())).cast<float>();
  sample_columns_.resize(static_cast<Eigen::Index>(points_.size()), 6);
  for (size_t i = 0; i < points_.size(); ++i) {
    sample_columns_.row(static_cast<Eigen::Index>(i)) << points_[i].transpose(),
        normals_[i].transpose();
  }
  sparse_ = SparseSubset(points_, normals_, bounds.min.cast<float>());
  BuildGrid(bounds, size);
}

void ProxyModel::BuildGrid(const Bounds3& bounds, const Eigen::Vector3d& size) {
  const float resolution = static_cast<float>(options_.grid_resolution);
  inverse_resolution_ = 1.0f / resolution;
  grid_origin_ = (bounds.min.array() - options_.grid_margin).cast<float>();
  size_t cells = 1;
  for (int d = 0; d < 3; ++d) {
    dims_[d] = static_cast<int>(std::ceil((size[d] + 2 * options_.grid_margin) / resolution)) + 1;
    dims_[d] = (dims_[d] + 3) / 4 * 4;
    block_dims_[d] = dims_[d] / 4;
    cells *= dims_[d];
  }
  if (cells > (size_t{64} << 20)) {
    ThrowBadValue("model.grid_resolution", FormatNumber(options_.grid_resolution),
                  "a coarser grid: " + std::to_string(cells) + " cells exceed 64 M");
  }
  const NearestSamples nearest =
      NearestSampleGrid(points_, GridShape{grid_origin_, resolution, dims_}, cells);
  // Blocks: fine where a cell lies within fine_distance of its sample, else coarse (the sample of
  // the cell nearest each 2^3 group's centre, its cell (1, 1, 1)).
  const size_t sx = 1, sy = dims_[0], sz = static_cast<size_t>(dims_[0]) * dims_[1];
  const float fine_squared = static_cast<float>(options_.fine_distance * options_.fine_distance);
  blocks_.assign(static_cast<size_t>(block_dims_[0]) * block_dims_[1] * block_dims_[2], 0);
  cells_.clear();
  for (int bz = 0; bz < block_dims_[2]; ++bz) {
    for (int by = 0; by < block_dims_[1]; ++by) {
      for (int bx = 0; bx < block_dims_[0]; ++bx) {
        // Cell (x, y, z) of the block, each 0..3; the block's k-th fine entry is cell
        // (k & 3, k >> 2 & 3, k >> 4), its k-th coarse entry cell (1, 1, 1) of 2^3 group
        // (k & 1, k >> 1 & 1, k >> 2), as Closest reads them.
        const size_t corner = 4 * (bz * sz + by * sy + bx * sx);
        auto cell = [&](int x, int y, int z) { return corner + z * sz + y * sy + x; };
        bool fine = false;
        for (int k = 0; k < 64 && !fine; ++k) {
          fine = nearest.best[cell(k & 3, k >> 2 & 3, k >> 4)] <= fine_squared;
        }
        const size_t b = (static_cast<size_t>(bz) * block_dims_[1] + by) * block_dims_[0] + bx;
        blocks_[b] = static_cast<uint32_t>(cells_.size()) << 1 | (fine ? 1 : 0);
        if (fine) {
          for (int k = 0; k < 64; ++k) {
            cells_.push_back(nearest.grid[cell(k & 3, k >> 2 & 3, k >> 4)]);
          }
        } else {
          for (int k = 0; k < 8; ++k) {
            cells_.push_back(
                nearest.grid[cell(2 * (k & 1) + 1, 2 * (k >> 1 & 1) + 1, 2 * (k >> 2) + 1)]);
          }
        }
      }
    }
  }
}

}  // namespace mmh::track
