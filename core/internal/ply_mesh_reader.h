// The PLY reader of LoadMesh (core/mesh_io.h): ASCII and binary (little and big endian) PLY as
// real models write it (BOP's models and models_eval, the Stanford scans, MeshLab, Blender,
// WritePly), without assimp. Paul Bourke's PLY format description is the reference.
#pragma once

#include <string>
#include <string_view>

#include "core/triangle_mesh.h"

namespace mmh::internal {

// Reads the whole PLY file `bytes` (named `where` in errors). The `vertex` element must have
// scalar x, y, z properties; red, green, blue (or r, g, b, or diffuse_red ...) give vertex colours
// (integer types scaled by their maximum, floats as they are); other vertex properties (normals,
// alpha, texture coordinates) are read and ignored. The `face` element's list property
// `vertex_indices` (or `vertex_index`) gives polygons, triangulated as fans; other face properties
// and other elements are read and ignored. Faces take their colour from their vertices (the mean)
// or are kDefaultMeshColor. Vertices are returned unscaled and not checked for being finite.
// Anything malformed -- header lines, types, counts the data cannot hold, ASCII tokens that are not
// numbers of their property's type, too few or too many values on an ASCII line, a binary body
// that ends early or has bytes left, an index out of range -- is an InputError naming the file,
// the header line or the element and item (with the ASCII line or the binary byte offset), the
// value and what was expected.
TriangleMesh ReadPlyMesh(std::string_view bytes, const std::string& where);

}  // namespace mmh::internal
