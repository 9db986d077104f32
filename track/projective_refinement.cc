#include "track/projective_refinement.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.h"
#include "track/internal/pose_update.h"
#include "track/point_to_plane_icp.h"

namespace mmh::track {

void ProjectiveOptions::Validate(const std::string& prefix) const {
  if (iterations < 0 || iterations > 100) {
    ThrowBadValue(prefix + ".iterations", std::to_string(iterations), "an integer in [0, 100]");
  }
  RequireNonNegative(rerender_px, prefix + ".rerender_px", "px");
  RequirePositive(max_distance, prefix + ".max_distance", "m");
  RequirePositive(max_residual, prefix + ".max_residual", "m");
  RequirePositive(huber, prefix + ".huber", "m");
  RequireNonNegative(min_rotation, prefix + ".min_rotation", "rad");
  RequireNonNegative(min_translation, prefix + ".min_translation", "m");
  RequireNonNegative(prior_rotation_deg, prefix + ".prior_rotation_deg", "deg");
  RequireNonNegative(prior_translation, prefix + ".prior_translation", "m");
}

namespace {

// The model's camera-facing samples z-buffered into an image window at a pose: per pixel the
// sample nearest the camera (-1: none).
class SampleBuffer {
 public:
  static constexpr size_t kSpareSlots = 16;  // a power of 2

  // The window [x0, x1] x [y0, y1] of an image with `intrinsics`.
  SampleBuffer(const PinholeIntrinsics& intrinsics, int x0, int y0, int x1, int y1)
      : x0_(x0), y0_(y0), width_(x1 - x0 + 1), height_(y1 - y0 + 1) {
    fx_ = static_cast<float>(intrinsics.fx);
    fy_ = static_cast<float>(intrinsics.fy);
    cx_ = static_cast<float>(intrinsics.cx) - x0;
    cy_ = static_cast<float>(intrinsics.cy) - y0;
  }

  void Render(const ProxyModel& model, const Eigen::Matrix3f& camera_R_proxy,
              const Eigen::Vector3f& camera_t_proxy) {
    const size_t size = static_cast<size_t>(width_) * height_;
    // kSpareSlots more slots than pixels: the samples not drawn go there, so that the z-buffer pass
    // has no branch to mispredict (whether a sample faces the camera, and whether it is nearer,
    // vary from sample to sample); spread over several slots, they do not wait for each other's
    // store to the same one.
    depth_.assign(size + kSpareSlots, std::numeric_limits<float>::infinity());
    sample_.assign(size + kSpareSlots, -1);
    const size_t count = model.points().size();
    // Two passes: the first, free of branches and scatter, vectorises (the facing test, the
    // projection and the window test per sample); the second z-buffers the samples it kept.
    // The camera's centre in the model frame: a sample faces the camera when n . (s - c) < 0.
    const Eigen::Vector3f center = -(camera_R_proxy.transpose() * camera_t_proxy);
    const Eigen::Matrix3f k = camera_R_proxy;
    const Eigen::Vector3f t = camera_t_proxy;
    const float width = static_cast<float>(width_), height = static_cast<float>(height_);
    pixel_.resize(count);
    z_.resize(count);
    const auto& columns = model.sample_columns();
    const float* __restrict sx = columns.col(0).data();
    const float* __restrict sy = columns.col(1).data();
    const float* __restrict sz = columns.col(2).data();
    const float* __restrict nx = columns.col(3).data();
    const float* __restrict ny = columns.col(4).data();
    const float* __restrict nz = columns.col(5).data();
    int* __restrict pixel = pixel_.data();
    float* __restrict depth = z_.data();
    const float cx = center.x(), cy = center.y(), cz = center.z();
    const float fx = fx_, fy = fy_, u0 = cx_ + 0.5f, v0 = cy_ + 0.5f;
    const int stride = width_;
    const float k00 = k(0, 0), k01 = k(0, 1), k02 = k(0, 2), k10 = k(1, 0), k11 = k(1, 1),
                k12 = k(1, 2), k20 = k(2, 0), k21 = k(2, 1), k22 = k(2, 2);
    const float tx = t.x(), ty = t.y(), tz = t.z();
    for (size_t c = 0; c < count; ++c) {
      const float px = sx[c], py = sy[c], pz = sz[c];
      const float facing = nx[c] * (px - cx) + ny[c] * (py - cy) + nz[c] * (pz - cz);
      const float qx = k00 * px + k01 * py + k02 * pz + tx;
      const float qy = k10 * px + k11 * py + k12 * pz + ty;
      const float qz = k20 * px + k21 * py + k22 * pz + tz;
      const float inverse_z = 1.0f / qz;
      // Pixel centres at integers: the pixel is floor(x + 0.5), taken only inside the window.
      const float x = fx * qx * inverse_z + u0;
      const float y = fy * qy * inverse_z + v0;
      // Bitwise &, not &&: no branch, so the loop vectorises.
      const bool keep = (facing < 0) & (qz > 0) & (x >= 0) & (y >= 0) & (x < width) & (y < height);
      const int column = static_cast<int>(std::min(std::max(x, 0.0f), width - 1));
      const int row = static_cast<int>(std::min(std::max(y, 0.0f), height - 1));
      pixel[c] = keep ? row * stride + column
                      : static_cast<int>(size) + static_cast<int>(c & (kSpareSlots - 1));
      depth[c] = qz;
    }
    for (size_t c = 0; c < count; ++c) {
      const int at = pixel_[c];
      // Written as arithmetic: GCC turns the equivalent ?: into a branch.
      const int nearer = -static_cast<int>(z_[c] < depth_[at]);  // all ones or zero
      depth_[at] = std::min(z_[c], depth_[at]);
      sample_[at] ^= (sample_[at] ^ static_cast<int>(c)) & nearer;
    }
  }

  // The sample at image pixel (u, v); where the samples left the pixel empty (they lie about
  // sample_spacing apart, a pixel can be larger or smaller), the front-most of its 8 neighbours'
  // (on noise-free frames of the Soldier this returns to 0.18 deg of the truth; the neighbour
  // nearest the point's depth, 0.24 deg).
  int At(int u, int v) const {
    u -= x0_, v -= y0_;
    const int own = sample_[static_cast<size_t>(v) * width_ + u];
    if (own >= 0) return own;
    int best = -1;
    float front = std::numeric_limits<float>::infinity();
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || vv < 0 || uu >= width_ || vv >= height_) continue;
        const size_t at = static_cast<size_t>(vv) * width_ + uu;
        if (sample_[at] >= 0 && depth_[at] < front) front = depth_[at], best = sample_[at];
      }
    }
    return best;
  }

 private:
  int x0_, y0_, width_, height_;
  float fx_, fy_, cx_, cy_;
  std::vector<float> depth_;
  std::vector<int> sample_;
  // Per model sample: its pixel in the window (a spare slot: not drawn) and depth [m].
  std::vector<int> pixel_;
  std::vector<float> z_;
};

}  // namespace

Rigid3 RefineProjective(const ProxyModel& model, const PinholeIntrinsics& intrinsics,
                        std::span<const Eigen::Vector3f> points, size_t scored,
                        double extra_distance, const Rigid3& proxy_T_camera,
                        const ProjectiveOptions& options, std::span<const uint8_t> sample_matches) {
  internal::PoseUpdate update(proxy_T_camera, options.huber,
                              options.prior_rotation_deg * M_PI / 180, options.prior_translation);
  scored = std::min(scored, points.size());
  // Each point's pixel (the points were measured at pixels, so the projection rounds exactly), and
  // the window the scored points span, one pixel wider for the neighbours' samples. Extra points
  // outside it (the hand, mostly) cannot lie on the model and are left out.
  const PinholeIntrinsics& in = intrinsics;
  std::vector<Eigen::Vector2i> pixels(points.size(), Eigen::Vector2i(-1, -1));
  int x0 = in.width, y0 = in.height, x1 = -1, y1 = -1;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!(p.z() > 0)) continue;
    const Eigen::Vector2d pixel = in.Project(p.cast<double>());
    const double x = pixel.x() + 0.5, y = pixel.y() + 0.5;
    if (!(x >= 0 && y >= 0 && x < in.width && y < in.height)) continue;
    const int u = static_cast<int>(x), v = static_cast<int>(y);
    pixels[i] = {u, v};
    if (i >= scored) continue;
    x0 = std::min(x0, u), y0 = std::min(y0, v), x1 = std::max(x1, u), y1 = std::max(y1, v);
  }
  if (x1 < x0) return proxy_T_camera;
  x0 = std::max(0, x0 - 1), y0 = std::max(0, y0 - 1);
  x1 = std::min(in.width - 1, x1 + 1), y1 = std::min(in.height - 1, y1 + 1);
  for (size_t i = scored; i < points.size(); ++i) {
    const Eigen::Vector2i& pixel = pixels[i];
    if (pixel.x() < x0 || pixel.y() < y0 || pixel.x() > x1 || pixel.y() > y1) pixels[i].x() = -1;
  }
  SampleBuffer buffer(in, x0, y0, x1, y1);
  const auto& model_points = model.points();
  const auto& model_normals = model.normals();
  const float huber = static_cast<float>(options.huber);
  const float limit = static_cast<float>(options.max_distance);
  const float extra_limit = std::min(limit, static_cast<float>(extra_distance));
  const float max_residual = static_cast<float>(options.max_residual);
  const bool colour = !sample_matches.empty();
  // The model reaches at most this far from the proxy's origin [m]; the nearest data depth [m].
  const double reach = model.center().cast<double>().norm() + model.radius();
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < scored; ++i) nearest = std::min(nearest, double{points[i].z()});
  bool render = true;
  for (int k = 0; k < options.iterations; ++k) {
    const Eigen::Matrix3f r = update.rotation.cast<float>();
    const Eigen::Vector3f t = update.translation.cast<float>();
    if (render) buffer.Render(model, r.transpose(), -(r.transpose() * t));
    internal::NormalEquations equations(huber);
    for (size_t i = 0; i < points.size(); ++i) {
      if (pixels[i].x() < 0) continue;
      const int c = buffer.At(pixels[i].x(), pixels[i].y());
      if (c < 0) continue;
      if (colour && !(sample_matches[c] & (i < scored ? kMatchesScored : kMatchesExtra))) continue;
      const Eigen::Vector3f s = r * points[i] + t;
      const Eigen::Vector3f d = s - model_points[c];
      const float max_distance = i < scored ? limit : extra_limit;
      if (d.squaredNorm() > max_distance * max_distance) continue;
      const Eigen::Vector3f& n = model_normals[c];
      const float residual = n.dot(d);
      if (std::abs(residual) > max_residual) continue;
      equations.Add(s, n, residual);
    }
    if (equations.used() < 6) break;
    double angle = 0.0, shift = 0.0;
    if (!update.Apply(equations, &angle, &shift)) break;
    if (angle < options.min_rotation && shift < options.min_translation) break;
    // The z-buffer is drawn again only when the step moved some part of the model by more than
    // rerender_px in the image; otherwise the correspondences stay and only their planes move.
    render = (angle * reach + shift) * intrinsics.fx / nearest > options.rerender_px;
  }
  return Rigid3(Eigen::Quaterniond(update.rotation).normalized(), update.translation);
}

}  // namespace mmh::track
