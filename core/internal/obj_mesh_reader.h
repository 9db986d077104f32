// The OBJ reader of LoadMesh (core/mesh_io.h), without assimp: the geometry statements of
// Wavefront's OBJ format (v, vt, vn, f) and the diffuse colours (Kd) of its MTL material files.
#pragma once

#include <filesystem>
#include <string_view>

#include "core/triangle_mesh.h"

namespace mmh::internal {

// Reads the OBJ text `text` of the file `path`. `v x y z` gives a vertex; `v x y z w` one at
// x/w, y/w, z/w; `v x y z r g b` one with its colour (channels in [0, 1], an extension many
// scanners write). `f` lines give polygons of at least three corners, each `v`, `v/vt`, `v//vn`
// or `v/vt/vn` with 1-based indices or negative ones counted back from the last vertex (texture
// coordinate and normal indices are checked, then ignored); polygons are triangulated as fans.
// `mtllib` files (beside the OBJ) give each `newmtl` its `Kd` colour (sRGB, as most tools take
// it); `usemtl` chooses the colour of the faces that follow. A triangle whose three corners have
// vertex colours takes their mean, any other its material's colour, or kDefaultMeshColor without
// one (also for a material file that is missing or a material it does not define, as other
// readers do). Points (`p`), lines (`l`), groups, smoothing and other statements are ignored.
// Malformed statements -- a number that is not one, a missing coordinate, an index of 0 or out of
// range, an infinite or NaN coordinate, w = 0, a face of fewer than three corners -- are
// InputErrors naming the file and line (the MTL file's for a bad Kd), the value and what was
// expected. Vertices are returned unscaled.
TriangleMesh ReadObjMesh(std::string_view text, const std::filesystem::path& path);

}  // namespace mmh::internal
