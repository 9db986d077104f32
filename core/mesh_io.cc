#include "core/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/internal/obj_mesh_reader.h"
#include "core/internal/ply_mesh_reader.h"
#include "core/text_parsing.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
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

  // Our own readers, not assimp's: Debian's assimp 5 aborted (ai_assert) or looped for ever on
  // malformed PLY files that fuzzing found (fuzz/regressions/mesh/), and its allocations made
  // every fuzzed input cost a whole-heap leak scan.
  TriangleMesh mesh = extension == ".ply" ? internal::ReadPlyMesh(ReadBinaryFile(path), where)
                                          : internal::ReadObjMesh(ReadTextFile(path), path);
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
