#include "core/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/internal/assimp_mesh_import.h"
#include "core/plugin.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// A PLY's header must end with an "end_header" line: assimp 5.2's PLY reader loops for ever on a
// header without one (a fuzz finding, fuzz/regressions/mesh/ply_without_end_header). Checked in
// the first MiB, far more than any real header.
void RequirePlyHeaderEnd(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string start(std::size_t{1} << 20, '\0');
  in.read(start.data(), static_cast<std::streamsize>(start.size()));
  start.resize(static_cast<std::size_t>(in.gcount()));
  if (start.find("\nend_header") == std::string::npos) {
    ThrowBadValue(path.string(), "a PLY header without an end_header line",
                  "a valid ply mesh");
  }
}

// Little-endian bytes whatever the host's byte order.
void PutU32(uint32_t value, std::string* out) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}
void PutFloat(float value, std::string* out) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  PutU32(bits, out);
}

}  // namespace

TriangleMesh LoadMesh(const fs::path& path, double scale) {
  const std::string where = path.string();
  if (!std::isfinite(scale) || scale <= 0) {
    ThrowBadValue(where + ": scale", FormatNumber(scale), "a finite scale factor > 0");
  }
  const std::string extension = LowerExtension(path);
  if (extension != ".obj" && extension != ".ply") {
    ThrowBadValue(where, "extension '" + path.extension().string() + "'",
                  "a mesh file ending in .obj or .ply");
  }
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    ThrowBadValue(where, fs::exists(path, ec) ? "something that is not a file" : "a missing file",
                  "an existing OBJ or PLY mesh file");
  }

  if (extension == ".ply") RequirePlyHeaderEnd(path);

  // assimp is loaded on the first mesh read (core/internal/assimp_mesh_import.h).
  static const auto import_mesh = reinterpret_cast<internal::ImportMeshFunction>(
      PluginSymbol(MMH_ASSIMP_MESH_IMPORT_PLUGIN, internal::kImportMeshSymbol));
  TriangleMesh mesh;
  std::string error;
  if (!import_mesh(path.string(), &mesh, &error)) {
    ThrowBadValue(where, "a file assimp cannot read (" + error + ")",
                  "a valid " + extension.substr(1) + " mesh");
  }
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Eigen::RowVector3f file_position = mesh.vertices.row(v);
    for (int c = 0; c < 3; ++c) {
      mesh.vertices(v, c) = static_cast<float>(file_position(c) * scale);
    }
    if (!mesh.vertices.row(v).allFinite()) {
      ThrowBadValue(where + ": vertex " + std::to_string(v),
                    "(" + FormatNumber(file_position(0)) + ", " + FormatNumber(file_position(1)) +
                        ", " + FormatNumber(file_position(2)) + ") (scaled by " +
                        FormatNumber(scale) + ")",
                    "finite coordinates");
    }
  }
  const Eigen::Index f = mesh.faces.rows();
  if (f == 0) ThrowBadValue(where, "a file without triangles", "a mesh with at least one triangle");
  ValidateMesh(mesh, where);
  return mesh;
}

void WritePly(const TriangleMesh& mesh, const fs::path& path, double scale) {
  const std::string where = path.string();
  if (!std::isfinite(scale) || scale <= 0) {
    ThrowBadValue(where + ": scale", FormatNumber(scale), "a finite scale factor > 0");
  }
  ValidateMesh(mesh, "mesh for " + where);
  const auto normals = FaceNormals(mesh);
  const Eigen::Index faces = mesh.faces.rows();

  std::string data =
      "ply\nformat binary_little_endian 1.0\ncomment written by mmh (MotionMontage harness)\n";
  data += "element vertex " + std::to_string(3 * faces) + "\n";
  data +=
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  data += "element face " + std::to_string(faces) + "\n";
  data += "property list uchar int vertex_indices\nend_header\n";
  data.reserve(data.size() + static_cast<size_t>(faces) * (3 * 27 + 13));
  for (Eigen::Index f = 0; f < faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const auto row = mesh.vertices.row(mesh.faces(f, k));
      for (int c = 0; c < 3; ++c) PutFloat(static_cast<float>(row(c) * scale), &data);
      for (int c = 0; c < 3; ++c) PutFloat(normals(f, c), &data);
      for (int c = 0; c < 3; ++c) data.push_back(static_cast<char>(mesh.face_colors(f, c)));
    }
  }
  for (Eigen::Index f = 0; f < faces; ++f) {
    data.push_back(3);
    for (int k = 0; k < 3; ++k) PutU32(static_cast<uint32_t>(3 * f + k), &data);
  }
  WriteFileAtomically(path, data);
}

}  // namespace mmh
