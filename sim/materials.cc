#include "sim/materials.h"

#include "core/error.h"

namespace mmh::sim {

void SurfaceMaterial::Validate(const std::string& prefix) const {
  RequireProbability(ir_albedo, prefix + ".ir_albedo");
  RequireProbability(specularity, prefix + ".specularity");
  RequireProbability(colour_contrast, prefix + ".colour_contrast");
  // The blur is summed per pixel over a window of (6 sigma)^2 samples: 3 mm at 0.5 m is about
  // 2 000 pattern samples a pixel.
  if (!(subsurface_mm >= 0 && subsurface_mm <= 3)) {
    ThrowBadValue(prefix + ".subsurface_mm", FormatNumber(subsurface_mm),
                  "a spread under the surface in [0, 3] mm (foam and skin: about 1)");
  }
}

void SceneMaterials::Validate(const std::string& prefix) const {
  table.Validate(prefix + ".table");
  floor.Validate(prefix + ".floor");
  tape.Validate(prefix + ".tape");
  backdrop.Validate(prefix + ".backdrop");
  props.Validate(prefix + ".props");
  proxy.Validate(prefix + ".proxy");
  skin.Validate(prefix + ".skin");
  slider.Validate(prefix + ".slider");
}

const SurfaceMaterial& SceneMaterials::ForObject(const std::string& name) const {
  if (name == "table") return table;
  if (name == "floor") return floor;
  if (name == "play_area_tape" || name == "like_box_tape") return tape;
  if (name == "backdrop") return backdrop;
  if (name == "proxy") return proxy;
  if (name == "hand") return skin;
  if (name == "slider") return slider;
  return props;
}

}  // namespace mmh::sim
