// Reading and writing triangle meshes: proxy models the tracker loads (the user's own scans or
// CAD models, BOP object models) and the simulator's meshes written for inspection (MeshLab) or
// for the BOP toolkit.
#pragma once

#include <filesystem>

#include "core/triangle_mesh.h"

namespace mmh {

// Reads an OBJ or PLY file (PLY in ASCII or binary; the extension decides, case-insensitive) with
// mmh's own readers (core/internal/ply_mesh_reader.h, obj_mesh_reader.h), triangulating polygons
// as fans and ignoring points and lines. Vertex positions are multiplied by `scale` (0.001 for the
// BOP datasets' millimetre models). Per-face colour, in order of preference: the mean of the
// face's vertex colours, the diffuse colour of its material (OBJ `Kd`, taken as sRGB as most tools
// do), kDefaultMeshColor. Vertices are kept as the file gives them (not welded, unused ones kept).
// A missing file, an unsupported extension, any malformed content (file and line or element, the
// value, the expectation), a file without triangles, non-finite vertices and a non-positive or
// non-finite scale are InputErrors.
TriangleMesh LoadMesh(const std::filesystem::path& path, double scale = 1.0);

// Writes a binary little-endian PLY (x y z nx ny nz as float, red green blue as uchar per vertex,
// `list uchar int vertex_indices` per face) atomically. Every face gets its own three vertices so
// that its colour survives in viewers that only know vertex colours (MeshLab, the BOP toolkit);
// the vertex normals are the face's normal. Vertex positions are multiplied by `scale` (1000 for a
// BOP model in millimetres). An invalid mesh (ValidateMesh) or an unwritable path is an InputError.
void WritePly(const TriangleMesh& mesh, const std::filesystem::path& path, double scale = 1.0);

}  // namespace mmh
