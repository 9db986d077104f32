// Surface materials in the IR band of the Kinect's projector (830 nm), for the structured-light
// sensor mode (docs/sensor.md, "Structured light"): how much of the projected speckle a surface
// returns to the IR camera.
#pragma once

#include <string>

namespace mmh::sim {

// Reflectance at 830 nm: a Lambertian part ir_albedo (1 - specularity) cos(theta) and a mirror
// lobe specularity cos(theta)^specular_exponent (the projector sits 7.5 cm beside the camera, so
// the lobe is seen only near normal incidence, where it saturates the IR image).
struct SurfaceMaterial {
  double ir_albedo = 0.5;    // diffuse reflectance in [0, 1]
  double specularity = 0.0;  // share of the reflection that is mirror-like, in [0, 1]
  // Printed surfaces: the share c in [0, 1] of the diffuse reflectance that follows each face's
  // colour, ir_albedo ((1 - c) + c max(R, G, B) / 255). Black print (carbon) absorbs at 830 nm,
  // while the dyes of coloured inks are largely transparent there, so a bright colour of any hue
  // stays bright: the brightest channel, not the luminance. 0: one albedo for the whole object.
  double colour_contrast = 0.0;
  // Translucent surfaces (foam, skin, wax): the diffuse return leaves the surface after
  // scattering beneath it, spread around the point the light entered by a Gaussian of this
  // standard deviation [mm] on the surface, so each projected dot comes back blurred
  // (docs/sensor.md, "Translucent surfaces"). 0: an opaque surface, each dot returned where it
  // lands. At most 3 mm (its cost per pixel grows with the square of the spread).
  double subsurface_mm = 0.0;

  template <class V>
  void VisitFields(V& v) {
    v("ir_albedo", ir_albedo);
    v("specularity", specularity);
    v("colour_contrast", colour_contrast);
    v("subsurface_mm", subsurface_mm);
  }
  void Validate(const std::string& prefix) const;
};

// The materials of the table-top scene's parts (config `scene.materials`). Sources for the
// defaults: near-infrared reflectance of light skin about 0.5-0.6 at 800-850 nm (Anderson and
// Parrish 1981); dyed ABS (Duplo) is largely transparent to its dyes in the NIR and returns
// 0.5-0.7; wood laminate 0.4-0.5 with a weak gloss; painted walls 0.6-0.8; the table's steel legs
// and the grey floor darker.
struct SceneMaterials {
  SurfaceMaterial table{0.45, 0.10};     // table top and legs
  SurfaceMaterial floor{0.30, 0.0};
  SurfaceMaterial tape{0.70, 0.05};      // play area and Like box tape
  SurfaceMaterial backdrop{0.65, 0.0};   // painted wall
  SurfaceMaterial props{0.55, 0.05};     // the castle (painted wood)
  SurfaceMaterial proxy{0.60, 0.15};     // Duplo ABS plastic (or any proxy model)
  SurfaceMaterial skin{0.55, 0.03};      // hand and forearm
  SurfaceMaterial slider{0.50, 0.20};    // the slider block (glossy plastic)

  template <class V>
  void VisitFields(V& v) {
    v("table", table);
    v("floor", floor);
    v("tape", tape);
    v("backdrop", backdrop);
    v("props", props);
    v("proxy", proxy);
    v("skin", skin);
    v("slider", slider);
  }
  void Validate(const std::string& prefix) const;
  // The material of a scene object by its RayScene name (table, floor, play_area_tape,
  // like_box_tape, backdrop, castle, proxy, hand, slider); props for any other name.
  const SurfaceMaterial& ForObject(const std::string& name) const;
};

}  // namespace mmh::sim
