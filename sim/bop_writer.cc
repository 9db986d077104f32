#include "sim/bop_writer.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"

namespace mmh::sim {
namespace {

// A JSON array of numbers in shortest round-trip form ("[1, 0, 0.5]").
template <class Range>
std::string JsonNumbers(const Range& values) {
  std::string text = "[";
  bool first = true;
  for (double v : values) {
    if (!first) text += ", ";
    first = false;
    text += FormatNumber(v);
  }
  return text + "]";
}

}  // namespace

void WriteBopSceneGt(const std::filesystem::path& path, const BopFrames& frames) {
  std::string text = "{\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    text += "  \"" + std::to_string(i) + "\": [";
    for (size_t k = 0; k < frames[i].size(); ++k) {
      const BopObjectPose& object = frames[i][k];
      const std::string where =
          path.string() + ", image " + std::to_string(i) + ", object " + std::to_string(k);
      if (object.obj_id < 1) {
        ThrowBadValue(where + ", obj_id", std::to_string(object.obj_id), "a BOP object id >= 1");
      }
      const Eigen::Quaterniond& q = object.camera_T_object.rotation;
      const double norm = q.norm();
      if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6) {
        ThrowBadValue(where + ", rotation norm", FormatNumber(norm), "a unit quaternion");
      }
      if (!object.camera_T_object.translation.allFinite()) {
        ThrowBadValue(where + ", translation", "a non-finite value", "finite metres");
      }
      const Eigen::Matrix3d rotation = q.normalized().toRotationMatrix();
      double r[9];
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) r[3 * row + col] = rotation(row, col);
      }
      // BOP translations are in millimetres.
      const Eigen::Vector3d t_mm = 1000.0 * object.camera_T_object.translation;
      const double t[3] = {t_mm.x(), t_mm.y(), t_mm.z()};
      text += std::string(k == 0 ? "" : ", ") + "{\"cam_R_m2c\": " + JsonNumbers(r) +
              ", \"cam_t_m2c\": " + JsonNumbers(t) +
              ", \"obj_id\": " + std::to_string(object.obj_id) + "}";
    }
    text += std::string("]") + (i + 1 < frames.size() ? "," : "") + "\n";
  }
  text += "}\n";
  WriteFileAtomically(path, text);
}

void WriteBopSceneCamera(const std::filesystem::path& path, const PinholeIntrinsics& intrinsics,
                         int frame_count, double depth_scale_m) {
  intrinsics.Validate(path.string() + ", intrinsics");
  if (frame_count < 0) {
    ThrowBadValue(path.string() + ", frame count", std::to_string(frame_count), "a count >= 0");
  }
  if (!std::isfinite(depth_scale_m) || depth_scale_m <= 0) {
    ThrowBadValue(path.string() + ", depth_scale", FormatNumber(depth_scale_m),
                  "a finite number > 0 metres per depth unit");
  }
  const double k[9] = {intrinsics.fx, 0, intrinsics.cx, 0, intrinsics.fy, intrinsics.cy, 0, 0, 1};
  // BOP: millimetres per depth unit (0.2 for TUM's 5000 units per metre).
  const std::string camera = "{\"cam_K\": " + JsonNumbers(k) +
                             ", \"depth_scale\": " + FormatNumber(1000.0 * depth_scale_m) + "}";
  std::string text = "{\n";
  for (int i = 0; i < frame_count; ++i) {
    text += "  \"" + std::to_string(i) + "\": " + camera + (i + 1 < frame_count ? "," : "") + "\n";
  }
  text += "}\n";
  WriteFileAtomically(path, text);
}

void WriteBopScene(const std::filesystem::path& scene_folder, const BopFrames& frames,
                   const PinholeIntrinsics& intrinsics, double depth_scale_m) {
  EnsureDirectory(scene_folder);
  WriteBopSceneCamera(scene_folder / "scene_camera.json", intrinsics,
                      static_cast<int>(frames.size()), depth_scale_m);
  WriteBopSceneGt(scene_folder / "scene_gt.json", frames);
}

}  // namespace mmh::sim
