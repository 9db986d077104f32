#include "track/appearance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"

namespace mmh::track {

void AppearanceOptions::Validate(const std::string& prefix) const {
  RequireNonNegative(margin, prefix + ".margin");
  RequireNonNegative(min_gain, prefix + ".min_gain");
  RequirePositive(depth_tolerance, prefix + ".depth_tolerance", "m");
  if (window < 0 || window > 20) {
    ThrowBadValue(prefix + ".window", std::to_string(window), "an integer in [0, 20] (px)");
  }
  if (min_samples < 3) {
    ThrowBadValue(prefix + ".min_samples", std::to_string(min_samples), ">= 3");
  }
}

AppearanceModel::AppearanceModel(const TriangleMesh& mesh, const std::string& where) {
  ValidateMesh(mesh, where);
  const auto normals = FaceNormals(mesh);
  bool coloured = false, patterned = false;
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Rgb8 colour = {mesh.face_colors(f, 0), mesh.face_colors(f, 1), mesh.face_colors(f, 2)};
    coloured = coloured || colour != kDefaultMeshColor;
    patterned = patterned || (mesh.face_colors.row(f) != mesh.face_colors.row(0));
    if (normals.row(f).isZero()) continue;  // degenerate: no side to be seen from
    const Eigen::Vector3f centroid = (mesh.vertices.row(mesh.faces(f, 0)) +
                                      mesh.vertices.row(mesh.faces(f, 1)) +
                                      mesh.vertices.row(mesh.faces(f, 2))).transpose() / 3.0f;
    points_.push_back(centroid);
    normals_.push_back(normals.row(f).transpose());
    colours_.push_back(mesh.face_colors.row(f).transpose().cast<float>());
  }
  if (!coloured) {
    throw InputError(where + ": the appearance model has no colours (every face is the default " +
                     std::to_string(kDefaultMeshColor[0]) + ", " +
                     std::to_string(kDefaultMeshColor[1]) + ", " +
                     std::to_string(kDefaultMeshColor[2]) +
                     "), expected vertex colours (PLY red, green, blue; OBJ v x y z r g b) or "
                     "material colours (OBJ Kd)");
  }
  if (!patterned) {
    throw InputError(where + ": every face of the appearance model has the colour " +
                     std::to_string(mesh.face_colors(0, 0)) + ", " +
                     std::to_string(mesh.face_colors(0, 1)) + ", " +
                     std::to_string(mesh.face_colors(0, 2)) +
                     ", expected a pattern (faces of different colours) to compare with the image");
  }
}

std::optional<double> AppearanceModel::Agreement(const RgbdFrame& frame,
                                                 const Rigid3& camera_T_model,
                                                 const AppearanceOptions& options) const {
  const PinholeIntrinsics& kd = frame.depth_intrinsics;
  const PinholeIntrinsics& kc = frame.color_intrinsics;
  if (frame.rgb.size() != static_cast<size_t>(kc.width) * kc.height * 3 || frame.rgb.empty()) {
    return std::nullopt;
  }
  const Eigen::Matrix3f r = camera_T_model.rotation.toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = camera_T_model.translation.cast<float>();
  const Rigid3 color_T_model = frame.color_T_depth * camera_T_model;
  const Eigen::Matrix3f rc = color_T_model.rotation.toRotationMatrix().cast<float>();
  const Eigen::Vector3f tc = color_T_model.translation.cast<float>();
  const float tolerance = static_cast<float>(options.depth_tolerance);
  const int radius = options.window;
  // Sums for the correlation of the chromaticities r = R / (R + G + B + 1) and g (the same with
  // G): model m, image o.
  std::array<double, 2> sm{}, so{}, smm{}, soo{}, smo{};
  int seen = 0;
  auto pixel = [](const PinholeIntrinsics& k, const Eigen::Vector3f& c, int* u, int* v) {
    const double x = k.fx * c.x() / c.z() + k.cx + 0.5;
    const double y = k.fy * c.y() / c.z() + k.cy + 0.5;
    if (!(x >= 0 && y >= 0 && x < k.width && y < k.height)) return false;
    *u = static_cast<int>(x);
    *v = static_cast<int>(y);
    return true;
  };
  for (size_t i = 0; i < points_.size(); ++i) {
    const Eigen::Vector3f c = r * points_[i] + t;
    if (c.z() <= 0.05f || (r * normals_[i]).dot(c) >= 0) continue;
    int u = 0, v = 0;
    if (!pixel(kd, c, &u, &v)) continue;
    const uint16_t d = frame.depth[static_cast<size_t>(v) * kd.width + u];
    if (d == 0 || std::abs(d * static_cast<float>(frame.depth_scale) - c.z()) > tolerance) continue;
    const Eigen::Vector3f cc = rc * points_[i] + tc;
    if (cc.z() <= 0.05f || !pixel(kc, cc, &u, &v)) continue;
    // The image's colour: the mean over the window around the pixel (within the image).
    Eigen::Vector3d observed = Eigen::Vector3d::Zero();
    int pixels = 0;
    for (int y = std::max(0, v - radius); y <= std::min(kc.height - 1, v + radius); ++y) {
      for (int x = std::max(0, u - radius); x <= std::min(kc.width - 1, u + radius); ++x) {
        const uint8_t* o = &frame.rgb[(static_cast<size_t>(y) * kc.width + x) * 3];
        observed += Eigen::Vector3d(o[0], o[1], o[2]);
        ++pixels;
      }
    }
    observed /= pixels;
    const Eigen::Vector3d model = colours_[i].cast<double>();
    for (int ch = 0; ch < 2; ++ch) {
      const double m = model[ch] / (model.sum() + 1), x = observed[ch] / (observed.sum() + 1);
      sm[ch] += m;
      so[ch] += x;
      smm[ch] += m * m;
      soo[ch] += x * x;
      smo[ch] += m * x;
    }
    ++seen;
  }
  if (seen < options.min_samples) return std::nullopt;
  double sum = 0.0;
  for (int ch = 0; ch < 2; ++ch) {
    const double var_m = smm[ch] - sm[ch] * sm[ch] / seen;
    const double var_o = soo[ch] - so[ch] * so[ch] / seen;
    // A chromaticity without variation on one side (1e-9 squared per sample, about 0.03 % of
    // its range) correlates with nothing.
    if (var_m <= 1e-9 * seen || var_o <= 1e-9 * seen) return std::nullopt;
    sum += (smo[ch] - sm[ch] * so[ch] / seen) / std::sqrt(var_m * var_o);
  }
  return sum / 2.0;
}

}  // namespace mmh::track
