// The proxy's model as the tracker uses it: surface samples with their faces' normals, and a
// closest-point grid around it, so that the ICP's correspondence search is one memory read
// (a precomputed nearest-neighbour field, as in distance-transform ICP; Fitzgibbon 2003).
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
  // bounds [m] (data farther from the model than that has no correspondence).
  double grid_resolution = 0.002;
  double grid_margin = 0.03;

  template <class V>
  void VisitFields(V& v) {
    v("sample_spacing", sample_spacing);
    v("grid_resolution", grid_resolution);
    v("grid_margin", grid_margin);
  }
  // spacing in [0.2 mm, 2 cm], resolution in [0.5 mm, 2 cm], margin in [5 mm, 20 cm].
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
  // #S: the mesh face each sample lies on (for its colour).
  const std::vector<int>& sample_faces() const { return sample_faces_; }

  // Index of the sample nearest to `model_p` (up to half a grid cell), or -1 outside the grid.
  int Closest(const Eigen::Vector3f& model_p) const {
    const Eigen::Vector3f g = (model_p - grid_origin_) * inverse_resolution_;
    const int x = static_cast<int>(g.x()), y = static_cast<int>(g.y()), z = static_cast<int>(g.z());
    if (g.x() < 0 || g.y() < 0 || g.z() < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) {
      return -1;
    }
    return grid_[(static_cast<size_t>(z) * dims_[1] + y) * dims_[0] + x];
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
  ProxyModelOptions options_;
  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> normals_;
  std::vector<int> sample_faces_;
  std::vector<int> sparse_;
  Eigen::Vector3f grid_origin_;
  float inverse_resolution_ = 1;
  int dims_[3] = {0, 0, 0};
  std::vector<int32_t> grid_;
  Eigen::Vector3f center_ = Eigen::Vector3f::Zero();
  float radius_ = 0;
  Eigen::Vector3f centroid_ = Eigen::Vector3f::Zero();
};

}  // namespace mmh::track
