// The part of LoadMesh (core/mesh_io.h) that calls assimp. It is built as a plugin,
// libmmh_assimp_mesh_import.so, which LoadMesh loads with dlopen when it first reads a mesh: assimp
// and what it links (Draco, minizip) cost every process about 10 ms and 4 MB at start otherwise,
// and most mmh commands read no mesh file (docs/architecture.md, "Start-up").
//
// Only assimp and header-only code (Eigen, the standard library) may be used here: the plugin
// links nothing of mmh.
#pragma once

#include <string>

#include "core/triangle_mesh.h"

namespace mmh::internal {

// Reads `path` with assimp (triangulated, points and lines dropped, node transforms applied) into
// `mesh`: vertex positions as the file gives them (unscaled, not checked), faces, and face colours
// as LoadMesh documents them. False, with assimp's message in `error`, when assimp cannot read it.
using ImportMeshFunction = bool (*)(const std::string& path, TriangleMesh* mesh,
                                    std::string* error);

// The plugin's exported entry point (an ImportMeshFunction).
inline constexpr const char* kImportMeshSymbol = "MmhImportMeshWithAssimp";

}  // namespace mmh::internal
