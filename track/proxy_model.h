// The proxy's model as the tracker uses it: surface samples with their faces' normals, and a
// closest-point grid around it, so that the ICP's correspondence search is two memory reads
// (a precomputed nearest-neighbour field, as in distance-transform ICP; Fitzgibbon 2003). The
// grid is fine near the surface and coarse away from it, so that it stays small enough for the
// cache.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"

namespace mmh::track {

struct ProxyModelOptions {
  // Spacing of the surface samples [m] (about one sample per spacing^2 of area).
  double sample_spacing = 0.0015;
  // Cell size of the closest-point grid [m]; the grid reaches grid_margin beyond the model's
  // bounds [m] (data farther from the model than that has no correspondence). A query gets the
  // sample nearest to its cell's centre, which near an edge of the model can lie on another face
  // than the query's own: with 2 mm cells that alone turned the ICP's fit on noise-free frames of
  // a Soldier take 0.40 deg (median) from the truth, with 1 mm cells 0.12 deg.
  double grid_resolution = 0.0015;
  double grid_margin = 0.03;
  // Beyond this distance from the nearest sample [m] the grid is coarse: blocks of 4^3 cells keep
  // one sample per 2^3 cells (the ICP's rejection distance shrinks to 6 mm; farther
  // correspondences only start its alignment).
  double fine_distance = 0.008;

  template <class V>
  void VisitFields(V& v) {
    v("sample_spacing", sample_spacing);
    v("grid_resolution", grid_resolution);
    v("grid_margin", grid_margin);
    v("fine_distance", fine_distance);
  }
  // spacing in [0.2 mm, 2 cm], resolution in [0.5 mm, 2 cm], margin in [5 mm, 20 cm],
  // fine_distance in [0, 20 cm].
  void Validate(const std::string& prefix) const;
};

class ProxyModel {
 public:
  // Validates the mesh (InputError naming `where`), samples it and builds the grid. A model larger
  // than 1 m or whose grid would exceed 64 M cells is an InputError (a millimetre model read as
  // metres, say).
  ProxyModel(const TriangleMesh& mesh, const ProxyModelOptions& options, const std::string& where);

  // #S by 3 sample positions and unit outward normals in the model frame.
  const std::vector<Eigen::Vector3f>& points() const { return points_; }
  const std::vector<Eigen::Vector3f>& normals() const { return normals_; }
  // #S by 6: the same, x y z nx ny nz, one contiguous column each (for loops that vectorise).
  const Eigen::Matrix<float, Eigen::Dynamic, 6>& sample_columns() const { return sample_columns_; }
  // #S: the mesh face each sample lies on (for its colour).
  const std::vector<int>& sample_faces() const { return sample_faces_; }

  // Index of the sample nearest to the centre of `model_p`'s cell (in the coarse level: of a cell
  // of its 2^3 group), or -1 outside the grid.
  int Closest(const Eigen::Vector3f& model_p) const {
    const Eigen::Vector3f g = (model_p - grid_origin_) * inverse_resolution_;
    const int x = static_cast<int>(g.x()), y = static_cast<int>(g.y()), z = static_cast<int>(g.z());
    if (g.x() < 0 || g.y() < 0 || g.z() < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) {
      return -1;
    }
    // Block of 4^3 cells: its first entry in cells_ << 1 | fine (64 entries, one per cell) or
    // coarse (8, one per 2^3 cells).
    const uint32_t block =
        blocks_[(static_cast<size_t>(z >> 2) * block_dims_[1] + (y >> 2)) * block_dims_[0] +
                (x >> 2)];
    const uint32_t first = block >> 1;
    if (block & 1) return cells_[first + ((z & 3) << 4 | (y & 3) << 2 | (x & 3))];
    return cells_[first + ((z & 2) << 1 | (y & 2) | (x & 2) >> 1)];
  }
  // The grid's size [bytes] (bench_track reports it).
  size_t grid_bytes() const {
    return blocks_.size() * sizeof(uint32_t) + cells_.size() * sizeof(int32_t);
  }

  // Centre of the bounding box and the radius of its bounding sphere [m], model frame.
  const Eigen::Vector3f& center() const { return center_; }
  float radius() const { return radius_; }
  // Mean of the surface samples (the area centroid) [m], model frame.
  const Eigen::Vector3f& centroid() const { return centroid_; }
  const ProxyModelOptions& options() const { return options_; }
  // A second, sparser set of samples (about 4 mm apart) for the free-space check.
  const std::vector<int>& sparse_samples() const { return sparse_; }

 private:
  // The nearest-sample grid over the model's bounds and its blocks (Closest's lookup), from the
  // samples.
  void BuildGrid(const Bounds3& bounds, const Eigen::Vector3d& size);

  ProxyModelOptions options_;
  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> normals_;
  Eigen::Matrix<float, Eigen::Dynamic, 6> sample_columns_;
  std::vector<int> sample_faces_;
  std::vector<int> sparse_;
  Eigen::Vector3f grid_origin_;
  float inverse_resolution_ = 1;
  int dims_[3] = {0, 0, 0};        // cells per axis, multiples of 4
  int block_dims_[3] = {0, 0, 0};  // dims_ / 4
  std::vector<uint32_t> blocks_;
  std::vector<int32_t> cells_;
  Eigen::Vector3f center_ = Eigen::Vector3f::Zero();
  float radius_ = 0;
  Eigen::Vector3f centroid_ = Eigen::Vector3f::Zero();
};

}  // namespace mmh::track
