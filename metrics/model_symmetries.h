// An object model's symmetries as the BOP benchmark declares them (models_info.json,
// bop_toolkit docs/bop_datasets_format.md): "symmetries_discrete", a list of 4x4 row-major
// object_T_symmetric matrices, and "symmetries_continuous", a list of {"axis": [3], "offset": [3]}
// (rotation by any angle about the axis through the offset point), discretised as bop_toolkit's
// misc.get_symmetry_transformations does for its error functions: every continuous symmetry in
// ceil(pi / max_step) equal steps of a full turn (max_step: the largest arc, in diameters, the
// point furthest from the axis travels between consecutive steps; BOP's evaluation uses 0.01), each
// step composed with each discrete symmetry and the identity.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <vector>

#include "core/rigid3.h"

namespace mmh::metrics {

struct ContinuousSymmetry {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // a point on the axis [m]
};

struct ModelSymmetries {
  std::vector<Rigid3> discrete;  // object_T_symmetric [m], without the identity
  std::vector<ContinuousSymmetry> continuous;
};

// The symmetries of every object in a BOP models_info.json ({"<obj_id>": {"diameter": ...,
// "symmetries_discrete": [[16]], "symmetries_continuous": [...]}}), translations and offsets
// multiplied by `scale` (the model's unit in metres: 0.001 for BOP's millimetres). An object
// without either key has none. Not a JSON object of objects, a matrix without 16 finite numbers
// or whose rotation is not one (orthonormal to 1e-3, determinant +1, last row 0 0 0 1), a zero
// axis: InputError naming the file, the object and the key.
std::map<int, ModelSymmetries> ReadModelsInfo(const std::filesystem::path& path, double scale);

// bop_toolkit's symmetry transformations (object_T_symmetric), the identity first: without
// continuous symmetries the identity and the discrete ones; with, for every discrete one D (and
// the identity) and every step k = 0 .. n-1 of every continuous one C (n = ceil(pi / max_step)),
// C_k D with C_k the rotation by 2 pi k / n about C's axis through its offset.
std::vector<Rigid3> SymmetryTransformations(const ModelSymmetries& symmetries,
                                            double max_step = 0.01);

}  // namespace mmh::metrics
