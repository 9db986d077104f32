#include "metrics/bop_errors.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "metrics/tracking_metrics.h"

namespace mmh::metrics {
namespace {

// x -> camera_T_gt * object_T_symmetric * x for each symmetry (the identity when none).
std::vector<Rigid3> SymmetricTruths(const Rigid3& camera_T_gt, const std::vector<Rigid3>& symmetries) {
  std::vector<Rigid3> truths = {camera_T_gt};
  for (const Rigid3& s : symmetries) truths.push_back(camera_T_gt * s);
  return truths;
}

}  // namespace

ModelPoints ErrorPoints(const TriangleMesh& mesh, int surface_points, int max_points) {
  const ModelPoints vertices = MetricPoints(mesh, max_points);
  if (vertices.rows() >= surface_points || mesh.face_count() == 0) return vertices;
  // Cumulative face areas; sample s picks the face at (s + 0.5) / n of the total area and a point
  // in it from the R2 sequence (Roberts 2018), folded into the triangle.
  std::vector<double> cumulative(mesh.face_count());
  double total = 0.0;
  for (int f = 0; f < mesh.face_count(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2)).cast<double>();
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[f] = total;
  }
  ModelPoints points(vertices.rows() + surface_points, 3);
  points.topRows(vertices.rows()) = vertices;
  constexpr double kG = 1.32471795724474602596;  // the plastic number
  for (int s = 0; s < surface_points; ++s) {
    const double target = (s + 0.5) / surface_points * total;
    const int f = static_cast<int>(std::lower_bound(cumulative.begin(), cumulative.end(), target) -
                                   cumulative.begin());
    double r1 = std::fmod(0.5 + (s + 1) / kG, 1.0), r2 = std::fmod(0.5 + (s + 1) / (kG * kG), 1.0);
    if (r1 + r2 > 1) {
      r1 = 1 - r1;
      r2 = 1 - r2;
    }
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2)).cast<double>();
    points.row(vertices.rows() + s) = (a + r1 * (b - a) + r2 * (c - a)).transpose();
  }
  return points;
}

namespace {

// The largest distance of a model point between the two poses [m].
double MaxDistance(const Rigid3& camera_T_a, const Rigid3& camera_T_b, const ModelPoints& points) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d x = points.row(i).transpose();
    worst = std::max(worst, (camera_T_a * x - camera_T_b * x).norm());
  }
  return worst;
}

}  // namespace

Rigid3 NearestSymmetricTruth(const Rigid3& camera_T_est, const Rigid3& camera_T_gt,
                             const ModelPoints& points, const std::vector<Rigid3>& symmetries) {
  Rigid3 nearest = camera_T_gt;
  double best = std::numeric_limits<double>::infinity();
  for (const Rigid3& truth : SymmetricTruths(camera_T_gt, symmetries)) {
    const double distance = MaxDistance(camera_T_est, truth, points);
    if (distance < best) {
      best = distance;
      nearest = truth;
    }
  }
  return nearest;
}

double Mssd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt, const ModelPoints& points,
            const std::vector<Rigid3>& symmetries) {
  return MaxDistance(camera_T_est,
                     NearestSymmetricTruth(camera_T_est, camera_T_gt, points, symmetries), points);
}

double Mspd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt, const ModelPoints& points,
            const PinholeIntrinsics& intrinsics, const std::vector<Rigid3>& symmetries) {
  double best = std::numeric_limits<double>::infinity();
  for (const Rigid3& truth : SymmetricTruths(camera_T_gt, symmetries)) {
    double worst = 0.0;
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      const Eigen::Vector3d x = points.row(i).transpose();
      worst = std::max(worst, (intrinsics.Project(camera_T_est * x) -
                               intrinsics.Project(truth * x)).norm());
    }
    best = std::min(best, worst);
  }
  return best;
}

std::vector<float> RenderDistance(const TriangleMesh& mesh, const Rigid3& camera_T_object,
                                  const PinholeIntrinsics& k) {
  const int w = k.width, h = k.height;
  // The z-buffer holds depth; distance = depth * |ray per unit depth| at the end.
  std::vector<float> depth(static_cast<size_t>(w) * h, std::numeric_limits<float>::infinity());
  const Eigen::Matrix3d r = camera_T_object.rotation.toRotationMatrix();
  for (int f = 0; f < mesh.face_count(); ++f) {
    Eigen::Vector3d c[3];
    double px[3], py[3];
    bool near = false;
    for (int j = 0; j < 3; ++j) {
      c[j] = r * mesh.vertices.row(mesh.faces(f, j)).cast<double>().transpose() +
             camera_T_object.translation;
      if (c[j].z() < 1e-3) near = true;
      px[j] = k.fx * c[j].x() / c[j].z() + k.cx;
      py[j] = k.fy * c[j].y() / c[j].z() + k.cy;
    }
    if (near) continue;
    const double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    if (area == 0) continue;
    const int u0 = std::max(0, static_cast<int>(std::ceil(std::min({px[0], px[1], px[2]}))));
    const int u1 = std::min(w - 1, static_cast<int>(std::floor(std::max({px[0], px[1], px[2]}))));
    const int v0 = std::max(0, static_cast<int>(std::ceil(std::min({py[0], py[1], py[2]}))));
    const int v1 = std::min(h - 1, static_cast<int>(std::floor(std::max({py[0], py[1], py[2]}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        // Barycentric weights of the pixel centre (u, v) in the image.
        double b[3];
        for (int j = 0; j < 3; ++j) {
          const int a = (j + 1) % 3, bb = (j + 2) % 3;
          b[j] = ((px[bb] - px[a]) * (v - py[a]) - (py[bb] - py[a]) * (u - px[a])) / area;
        }
        if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
        // 1/z is affine in the image (perspective-correct interpolation).
        const double inverse_z = b[0] / c[0].z() + b[1] / c[1].z() + b[2] / c[2].z();
        const float z = static_cast<float>(1.0 / inverse_z);
        float& slot = depth[static_cast<size_t>(v) * w + u];
        slot = std::min(slot, z);
      }
    }
  }
  std::vector<float> distance(depth.size(), 0.0f);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float z = depth[static_cast<size_t>(v) * w + u];
      if (!std::isfinite(z)) continue;
      distance[static_cast<size_t>(v) * w + u] =
          static_cast<float>(k.BackProject(u, v, z).norm());
    }
  }
  return distance;
}

std::vector<float> DepthToDistance(const std::vector<uint16_t>& depth, double depth_scale,
                                   const PinholeIntrinsics& k) {
  std::vector<float> distance(depth.size(), 0.0f);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const size_t i = static_cast<size_t>(v) * k.width + u;
      if (depth[i] == 0) continue;
      distance[i] = static_cast<float>(k.BackProject(u, v, depth[i] * depth_scale).norm());
    }
  }
  return distance;
}

std::vector<double> Vsd(const Rigid3& camera_T_est, const Rigid3& camera_T_gt,
                        const TriangleMesh& mesh, const std::vector<float>& test,
                        const PinholeIntrinsics& k, double delta, const std::vector<double>& taus) {
  const std::vector<float> est = RenderDistance(mesh, camera_T_est, k);
  const std::vector<float> gt = RenderDistance(mesh, camera_T_gt, k);
  if (test.size() != gt.size()) {
    ThrowBadValue("VSD test distance image", std::to_string(test.size()) + " pixels",
                  std::to_string(gt.size()) + " (the intrinsics' size)");
  }
  // BOP'19 visibility: rendered, and the test image has no depth there or is not nearer by more
  // than delta. The estimate is also visible where the truth is and it is rendered.
  auto visible = [&](float model, float observed) {
    return model > 0 && (observed == 0 || model - observed <= delta);
  };
  size_t union_count = 0, complement = 0;
  std::vector<double> differences;
  for (size_t i = 0; i < gt.size(); ++i) {
    const bool visible_gt = visible(gt[i], test[i]);
    const bool visible_est = visible(est[i], test[i]) || (visible_gt && est[i] > 0);
    if (!visible_gt && !visible_est) continue;
    ++union_count;
    if (visible_gt && visible_est) {
      differences.push_back(std::abs(static_cast<double>(gt[i]) - est[i]));
    } else {
      ++complement;
    }
  }
  std::vector<double> errors;
  for (double tau : taus) {
    if (union_count == 0) {
      errors.push_back(1.0);
      continue;
    }
    const size_t costly = std::count_if(differences.begin(), differences.end(),
                                        [tau](double d) { return d >= tau; });
    errors.push_back(static_cast<double>(costly + complement) / union_count);
  }
  return errors;
}

void BopRecallOptions::Validate(const std::string& prefix) const {
  if (diameter_fractions.empty()) {
    ThrowBadValue(prefix + ".diameter_fractions", "[]", "at least one fraction");
  }
  for (double f : diameter_fractions) RequirePositive(f, prefix + ".diameter_fractions");
  if (mspd_pixels.empty()) ThrowBadValue(prefix + ".mspd_pixels", "[]", "at least one threshold");
  for (double p : mspd_pixels) RequirePositive(p, prefix + ".mspd_pixels", "px");
  RequirePositive(vsd_delta, prefix + ".vsd_delta", "m");
  RequirePositive(add_fraction, prefix + ".add_fraction");
}

BopRecall SummarizeBop(const std::vector<BopFrameErrors>& frames, double diameter, int image_width,
                       const BopRecallOptions& o) {
  BopRecall recall;
  recall.frames = static_cast<int>(frames.size());
  if (frames.empty()) return recall;
  const double n = static_cast<double>(frames.size());
  auto share = [&](auto correct) {
    return std::count_if(frames.begin(), frames.end(),
                         [&](const BopFrameErrors& e) { return e.has_estimate && correct(e); }) /
           n;
  };
  double mssd = 0, mspd = 0, vsd = 0;
  const double pixel_scale = image_width / 640.0;
  for (double f : o.diameter_fractions) {
    mssd += share([&](const BopFrameErrors& e) { return e.mssd < f * diameter; });
  }
  for (double p : o.mspd_pixels) {
    mspd += share([&](const BopFrameErrors& e) { return e.mspd < p * pixel_scale; });
  }
  recall.has_vsd = std::any_of(frames.begin(), frames.end(),
                               [](const BopFrameErrors& e) { return !e.vsd.empty(); });
  for (size_t t = 0; t < o.diameter_fractions.size(); ++t) {
    for (double threshold : o.diameter_fractions) {
      vsd += share([&](const BopFrameErrors& e) { return t < e.vsd.size() && e.vsd[t] < threshold; });
    }
  }
  recall.ar_mssd = mssd / o.diameter_fractions.size();
  recall.ar_mspd = mspd / o.mspd_pixels.size();
  recall.ar_vsd = vsd / (o.diameter_fractions.size() * o.diameter_fractions.size());
  recall.ar = recall.has_vsd ? (recall.ar_vsd + recall.ar_mssd + recall.ar_mspd) / 3
                             : (recall.ar_mssd + recall.ar_mspd) / 2;
  recall.add_recall = share([&](const BopFrameErrors& e) { return e.add < o.add_fraction * diameter; });
  recall.adds_recall =
      share([&](const BopFrameErrors& e) { return e.adds < o.add_fraction * diameter; });
  recall.recall_5deg_5cm =
      share([](const BopFrameErrors& e) { return e.rotation_deg <= 5 && e.translation <= 0.05; });
  recall.recall_2deg_2cm =
      share([](const BopFrameErrors& e) { return e.rotation_deg <= 2 && e.translation <= 0.02; });
  std::vector<double> rotations, translations;
  for (const auto& e : frames) {
    if (!e.has_estimate) continue;
    rotations.push_back(e.rotation_deg);
    translations.push_back(e.translation);
  }
  recall.median_rotation_deg = Quantile(rotations, 0.5);
  recall.median_translation = Quantile(translations, 0.5);
  return recall;
}

nlohmann::json ToJson(const BopRecall& r) {
  nlohmann::json j = {{"frames", r.frames},
                      {"ar", r.ar},
                      {"ar_mssd", r.ar_mssd},
                      {"ar_mspd", r.ar_mspd},
                      {"add_recall", r.add_recall},
                      {"adds_recall", r.adds_recall},
                      {"recall_5deg_5cm", r.recall_5deg_5cm},
                      {"recall_2deg_2cm", r.recall_2deg_2cm},
                      {"median_rotation_deg", r.median_rotation_deg},
                      {"median_translation_mm", r.median_translation * 1000}};
  j["ar_vsd"] = r.has_vsd ? nlohmann::json(r.ar_vsd) : nlohmann::json(nullptr);
  return j;
}

}  // namespace mmh::metrics
