#include "core/mesh_io.h"

#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

uint8_t ToByte(float value) {
  const float clamped = std::clamp(std::isfinite(value) ? value : 0.0f, 0.0f, 1.0f);
  return static_cast<uint8_t>(std::lround(clamped * 255.0f));
}

// The diffuse colour of a material, or kDefaultMeshColor for assimp's placeholder material (a file
// that names no material) or a material without one.
Rgb8 MaterialColor(const aiScene& scene, unsigned material_index) {
  if (material_index >= scene.mNumMaterials) return kDefaultMeshColor;
  const aiMaterial* material = scene.mMaterials[material_index];
  aiString name;
  if (material->Get(AI_MATKEY_NAME, name) == aiReturn_SUCCESS &&
      std::strcmp(name.C_Str(), AI_DEFAULT_MATERIAL_NAME) == 0) {
    return kDefaultMeshColor;
  }
  aiColor4D diffuse;
  if (material->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) != aiReturn_SUCCESS) return kDefaultMeshColor;
  return {ToByte(diffuse.r), ToByte(diffuse.g), ToByte(diffuse.b)};
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

  Assimp::Importer importer;
  // Points and lines are dropped: a proxy model is a surface.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_Triangulate | aiProcess_SortByPType |
                         aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    ThrowBadValue(where,
                  "a file assimp cannot read (" + std::string(importer.GetErrorString()) + ")",
                  "a valid " + extension.substr(1) + " mesh");
  }

  TriangleMesh mesh;
  size_t vertex_total = 0;
  size_t face_total = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    vertex_total += scene->mMeshes[m]->mNumVertices;
    face_total += scene->mMeshes[m]->mNumFaces;
  }
  mesh.vertices.resize(static_cast<Eigen::Index>(vertex_total), 3);
  mesh.faces.resize(static_cast<Eigen::Index>(face_total), 3);
  mesh.face_colors.resize(static_cast<Eigen::Index>(face_total), 3);
  Eigen::Index v = 0;
  Eigen::Index f = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    const auto first_vertex = static_cast<uint32_t>(v);
    for (unsigned i = 0; i < part.mNumVertices; ++i, ++v) {
      const aiVector3D& p = part.mVertices[i];
      mesh.vertices.row(v) << static_cast<float>(p.x * scale), static_cast<float>(p.y * scale),
          static_cast<float>(p.z * scale);
      if (!mesh.vertices.row(v).allFinite()) {
        ThrowBadValue(where + ": vertex " + std::to_string(v),
                      "(" + FormatNumber(p.x) + ", " + FormatNumber(p.y) + ", " +
                          FormatNumber(p.z) + ") (scaled by " + FormatNumber(scale) + ")",
                      "finite coordinates");
      }
    }
    const Rgb8 material_color = MaterialColor(*scene, part.mMaterialIndex);
    const aiColor4D* colors = part.mColors[0];
    for (unsigned i = 0; i < part.mNumFaces; ++i) {
      const aiFace& face = part.mFaces[i];
      if (face.mNumIndices != 3) continue;  // SortByPType removed the rest; be safe anyway
      float sum[3] = {0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        mesh.faces(f, k) = first_vertex + face.mIndices[k];
        if (colors != nullptr) {
          sum[0] += colors[face.mIndices[k]].r;
          sum[1] += colors[face.mIndices[k]].g;
          sum[2] += colors[face.mIndices[k]].b;
        }
      }
      for (int k = 0; k < 3; ++k) {
        mesh.face_colors(f, k) = colors != nullptr ? ToByte(sum[k] / 3.0f) : material_color[k];
      }
      ++f;
    }
  }
  mesh.faces.conservativeResize(f, Eigen::NoChange);
  mesh.face_colors.conservativeResize(f, Eigen::NoChange);
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
