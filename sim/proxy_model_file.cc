// LoadProxyModel and LoadSceneObjects (declared in sim/render_session.h) in a file of their own:
// mmh compose, mmh run's light executable and the report read proxy models too, and linking them
// must not pull in the renderer (Embree) or the image writers (docs/architecture.md, "Start-up").
#include <string>
#include <vector>

#include "core/error.h"
#include "core/mesh_io.h"
#include "sim/duplo.h"
#include "sim/render_session.h"

namespace mmh::sim {

TriangleMesh LoadProxyModel(const std::string& proxy, double scale) {
  if (proxy.empty()) return BuildDuploMesh(SoldierProxy());
  if (proxy.ends_with(".json")) return BuildDuploMesh(LoadDuploAssembly(proxy));
  return LoadMesh(proxy, scale);
}

std::vector<TriangleMesh> LoadSceneObjects(const TableSceneOptions& scene) {
  std::vector<TriangleMesh> meshes;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const SceneObject& o = scene.objects[i];
    try {
      meshes.push_back(LoadProxyModel(o.mesh, o.scale));
    } catch (const InputError& e) {
      throw InputError("scene.objects[" + std::to_string(i) + "].mesh (" + o.name +
                       "): " + e.what());
    }
  }
  return meshes;
}

}  // namespace mmh::sim
