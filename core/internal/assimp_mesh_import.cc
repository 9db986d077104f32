// The assimp plugin of LoadMesh (core/internal/assimp_mesh_import.h).
#include "core/internal/assimp_mesh_import.h"

#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstring>

namespace mmh::internal {
namespace {

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

bool ImportMesh(const std::string& path, TriangleMesh* mesh, std::string* error) {
  Assimp::Importer importer;
  // Points and lines are dropped: a proxy model is a surface.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_PreTransformVertices |
                aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    *error = importer.GetErrorString();
    return false;
  }

  size_t vertex_total = 0;
  size_t face_total = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    vertex_total += scene->mMeshes[m]->mNumVertices;
    face_total += scene->mMeshes[m]->mNumFaces;
  }
  mesh->vertices.resize(static_cast<Eigen::Index>(vertex_total), 3);
  mesh->faces.resize(static_cast<Eigen::Index>(face_total), 3);
  mesh->face_colors.resize(static_cast<Eigen::Index>(face_total), 3);
  Eigen::Index v = 0;
  Eigen::Index f = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    const auto first_vertex = static_cast<uint32_t>(v);
    for (unsigned i = 0; i < part.mNumVertices; ++i, ++v) {
      const aiVector3D& p = part.mVertices[i];
      mesh->vertices.row(v) << p.x, p.y, p.z;
    }
    const Rgb8 material_color = MaterialColor(*scene, part.mMaterialIndex);
    const aiColor4D* colors = part.mColors[0];
    for (unsigned i = 0; i < part.mNumFaces; ++i) {
      const aiFace& face = part.mFaces[i];
      if (face.mNumIndices != 3) continue;  // SortByPType removed the rest; be safe anyway
      float sum[3] = {0, 0, 0};
      for (int k = 0; k < 3; ++k) {
        mesh->faces(f, k) = first_vertex + face.mIndices[k];
        if (colors != nullptr) {
          sum[0] += colors[face.mIndices[k]].r;
          sum[1] += colors[face.mIndices[k]].g;
          sum[2] += colors[face.mIndices[k]].b;
        }
      }
      for (int k = 0; k < 3; ++k) {
        mesh->face_colors(f, k) = colors != nullptr ? ToByte(sum[k] / 3.0f) : material_color[k];
      }
      ++f;
    }
  }
  mesh->faces.conservativeResize(f, Eigen::NoChange);
  mesh->face_colors.conservativeResize(f, Eigen::NoChange);
  return true;
}

}  // namespace
}  // namespace mmh::internal

// The entry point LoadMesh looks up with dlsym; its type is checked against ImportMeshFunction.
extern "C" __attribute__((visibility("default"))) bool MmhImportMeshWithAssimp(
    const std::string& path, mmh::TriangleMesh* mesh, std::string* error) {
  static_assert(std::is_same_v<decltype(&MmhImportMeshWithAssimp),
                               mmh::internal::ImportMeshFunction>);
  return mmh::internal::ImportMesh(path, mesh, error);
}
