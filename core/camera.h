// Pinhole cameras. Pixel (u, v) = (column, row) has its centre at integer coordinates (the TUM /
// ROS convention, so the principal point of a 640x480 camera is (319.5, 239.5)). Camera frame:
// x right, y down, z forward (docs/notation.md).
#pragma once

#include <Eigen/Core>
#include <string>

namespace mmh {

struct PinholeIntrinsics {
  // Image size [px].
  int width = 640;
  int height = 480;
  // Focal lengths and principal point [px]. Defaults: the ROS default intrinsics of the Kinect v1
  // registered depth / colour image (DESIGN.md, "Kinect v1 model").
  double fx = 525.0;
  double fy = 525.0;
  double cx = 319.5;
  double cy = 239.5;

  template <class V>
  void VisitFields(V& v) {
    v("width", width);
    v("height", height);
    v("fx", fx);
    v("fy", fy);
    v("cx", cx);
    v("cy", cy);
  }
  // Sizes in [1, 16384], focal lengths finite and > 0, principal point finite and inside the
  // image (within one image size of it: off-centre crops are legal, nonsense is not).
  void Validate(const std::string& prefix) const;

  int pixel_count() const { return width * height; }

  // Pixel coordinates of a camera-frame point (z > 0).
  Eigen::Vector2d Project(const Eigen::Vector3d& camera_p) const {
    return {fx * camera_p.x() / camera_p.z() + cx, fy * camera_p.y() / camera_p.z() + cy};
  }
  // The camera-frame point at depth z (along the optical axis, not along the ray) seen at (u, v).
  Eigen::Vector3d BackProject(double u, double v, double z) const {
    return {(u - cx) / fx * z, (v - cy) / fy * z, z};
  }
};

bool operator==(const PinholeIntrinsics& a, const PinholeIntrinsics& b);

}  // namespace mmh
