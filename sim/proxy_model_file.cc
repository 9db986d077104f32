// LoadProxyModel (declared in sim/render_session.h) in a file of its own: mmh compose and the
// report read proxy models too, and linking them must not pull in the renderer (Embree) or the
// image writers (docs/architecture.md, "Start-up").
#include <string>

#include "core/mesh_io.h"
#include "sim/duplo.h"
#include "sim/render_session.h"

namespace mmh::sim {

TriangleMesh LoadProxyModel(const std::string& proxy, double scale) {
  if (proxy.empty()) return BuildDuploMesh(SoldierProxy());
  if (proxy.ends_with(".json")) return BuildDuploMesh(LoadDuploAssembly(proxy));
  return LoadMesh(proxy, scale);
}

}  // namespace mmh::sim
