// Appearance check: tells apart the poses that the depth cannot (a box turned over, whose half
// turns fill the same space) by the colours of a coloured model. The model's colours (one sample
// per face: its centroid, outward normal and colour, e.g. a YCB scan's texture baked to vertex
// colours) are projected at a candidate pose into the colour image, and where the depth confirms
// that the sample is seen (it faces the camera and the depth at its pixel lies within a tolerance
// of it), its colour is compared with the image's around that pixel. The agreement is the
// zero-mean normalised cross-correlation of the two chromaticities r = R / (R + G + B) and
// g = G / (R + G + B) (each plus 1 in the sum), averaged over r and g: the brightness drops out
// (the shading of faces at other angles to the light, the exposure), and the correlation's own
// gain and offset absorb most of a white balance, so the printing's pattern of hues is what
// counts. (The correlation of R, G and B themselves was tried first: on YCB-Video's gelatin box it
// followed the shading of the faces, 0.34 for the true pose against 0.36 for one turned over;
// the chromaticities' 0.53 against 0.22 tell them apart.)
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace mmh::track {

struct AppearanceOptions {
  // A detection ranks its verified poses by the depth (ProxyTracker's score); among those scoring
  // within `margin` of the best (the depth cannot tell them apart: the gelatin box's half turns
  // differ by 0.01 or less), the one whose model colours agree best with the colour image wins,
  // when its agreement exceeds the depth winner's by min_gain (0: off, the depth decides).
  double margin = 0.0;
  double min_gain = 0.1;
  // A model sample is seen when it faces the camera and the depth at its pixel lies within
  // depth_tolerance [m] of its own (not hidden by another surface, nor missing).
  double depth_tolerance = 0.01;
  // An agreement needs at least this many seen samples [samples]; with fewer there is none and
  // the depth decides.
  int min_samples = 100;
  // The image's colour at a sample: the mean over the (2 window + 1)^2 pixels around its pixel
  // [px] (the scan's colours and the pose are not exact to a pixel: on the gelatin box the true
  // pose's agreement rises from 0.53 to 0.64 with 2, the turned pose's stays at 0.1-0.2).
  int window = 2;

  template <class V>
  void VisitFields(V& v) {
    v("margin", margin);
    v("min_gain", min_gain);
    v("depth_tolerance", depth_tolerance);
    v("min_samples", min_samples);
    v("window", window);
  }
  void Validate(const std::string& prefix) const;
};

class AppearanceModel {
 public:
  // The samples of `mesh` (its faces' centroids, normals and colours, in the tracked model's frame
  // and unit). InputError naming `where` when the mesh has no colours (every face has
  // kDefaultMeshColor: a file without vertex or material colours) or all faces one colour (no
  // pattern to compare).
  AppearanceModel(const TriangleMesh& mesh, const std::string& where);

  // The agreement (in [-1, 1]) of the model's colours at camera_T_model (the depth camera's) with
  // frame.rgb; nullopt when fewer than options.min_samples samples are seen, or a channel is flat
  // on either side (no pattern to correlate), or the frame has no colour image.
  std::optional<double> Agreement(const RgbdFrame& frame, const Rigid3& camera_T_model,
                                  const AppearanceOptions& options) const;

  size_t size() const { return points_.size(); }

 private:
  std::vector<Eigen::Vector3f> points_, normals_, colours_;
};

}  // namespace mmh::track
