#include "track/recording.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "core/error.h"
#include "core/image_io.h"
#include "core/json_text.h"
#include "track/mat_file.h"

namespace mmh::track {
namespace fs = std::filesystem;

const char* RecordingLayoutName(RecordingLayout layout) {
  return layout == RecordingLayout::kBop ? "BOP scene" : "YCB-Video folder";
}

namespace {

constexpr const char* kYcbDepthSuffix = "-depth.png";

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// `count` finite numbers under `key` of `object`; InputError naming `where` and the key otherwise.
std::vector<double> Numbers(const nlohmann::json& object, const std::string& key, size_t count,
                            const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(where + ": '" + key + "' is missing");
  if (!it->is_array() || it->size() != count) {
    ThrowBadValue(where + ": '" + key + "'", it->dump(), std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (const auto& v : *it) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      ThrowBadValue(where + ": '" + key + "'", it->dump(), std::to_string(count) + " finite numbers");
    }
    values.push_back(v.get<double>());
  }
  return values;
}

int ImageId(const std::string& key, const fs::path& file) {
  char* end = nullptr;
  const long id = std::strtol(key.c_str(), &end, 10);
  if (key.empty() || *end != '\0' || id < 0) {
    ThrowBadValue(file.string() + ": key \"" + key + "\"", key, "an image id (integer >= 0)");
  }
  return static_cast<int>(id);
}

// The image <id:06d>.<ext> in the first of `dirs` (under `folder`) that has one; empty if none.
fs::path FindImage(const fs::path& folder, const std::vector<std::string>& dirs, int id) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d", id);
  for (const std::string& dir : dirs) {
    for (const char* ext : {".png", ".jpg", ".tif"}) {
      const fs::path p = folder / dir / (std::string(name) + ext);
      if (fs::exists(p)) return p;
    }
  }
  return {};
}

PinholeIntrinsics FromK(const double k[9], int width, int height, const std::string& where) {
  PinholeIntrinsics intrinsics;
  intrinsics.width = width;
  intrinsics.height = height;
  intrinsics.fx = k[0];
  intrinsics.fy = k[4];
  intrinsics.cx = k[2];
  intrinsics.cy = k[5];
  if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1) {
    throw InputError(where + ": the camera matrix is not [fx 0 cx; 0 fy cy; 0 0 1] (skew or a "
                             "bottom row other than 0 0 1)");
  }
  intrinsics.Validate(where);
  return intrinsics;
}

}  // namespace

Rigid3 PoseFromRowMajor(const double r[9], const double t[3], double t_to_metres,
                        const std::string& where) {
  Eigen::Matrix3d m;
  m << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  if (!m.allFinite() || !std::isfinite(t[0]) || !std::isfinite(t[1]) || !std::isfinite(t[2])) {
    throw InputError(where + ": a non-finite pose");
  }
  const double orthogonality = (m * m.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-3 || m.determinant() < 0) {
    ThrowBadValue(where + ": rotation",
                  "a matrix with |R R^T - I| = " + FormatNumber(orthogonality) +
                      ", det " + FormatNumber(m.determinant()),
                  "a rotation (orthonormal within 1e-3, det +1)");
  }
  // Re-orthonormalised: datasets store 6-8 significant digits.
  const Eigen::Quaterniond q(m);
  return Rigid3(q.normalized(), Eigen::Vector3d(t[0], t[1], t[2]) * t_to_metres);
}

std::optional<RecordingLayout> DetectRecordingLayout(const fs::path& folder) {
  if (fs::exists(folder / "scene_gt.json") || fs::exists(folder / "scene_camera.json")) {
    return RecordingLayout::kBop;
  }
  if (!fs::is_directory(folder)) return std::nullopt;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (EndsWith(entry.path().filename().string(), kYcbDepthSuffix)) {
      return RecordingLayout::kYcbVideo;
    }
  }
  return std::nullopt;
}

RecordingFrameSource::RecordingFrameSource(const fs::path& folder, double frame_rate)
    : folder_(folder), frame_rate_(frame_rate) {
  if (!(frame_rate > 0) || !std::isfinite(frame_rate)) {
    ThrowBadValue("frame rate", FormatNumber(frame_rate), "a positive number of frames per second");
  }
  const std::optional<RecordingLayout> layout = DetectRecordingLayout(folder);
  if (!layout) {
    throw InputError(folder.string() +
                     ": neither a BOP scene (scene_camera.json, scene_gt.json) nor a YCB-Video "
                     "folder (NNNNNN-depth.png with NNNNNN-meta.mat)");
  }
  layout_ = *layout;
  if (layout_ == RecordingLayout::kBop) {
    ReadBop();
  } else {
    ReadYcbVideo();
  }
  if (frames_.empty()) throw InputError(folder.string() + ": the recording has no frame");
}

void RecordingFrameSource::ReadBop() {
  const fs::path camera_file = folder_ / "scene_camera.json";
  const fs::path gt_file = folder_ / "scene_gt.json";
  const fs::path info_file = folder_ / "scene_gt_info.json";
  if (!fs::exists(camera_file)) {
    throw InputError(camera_file.string() + " is missing (the per-image intrinsics and depth scale "
                     "of a BOP scene)");
  }
  if (!fs::exists(gt_file)) {
    throw InputError(gt_file.string() + " is missing (the per-image ground-truth poses)");
  }
  const nlohmann::json cameras = ReadJsonFile(camera_file);
  const nlohmann::json gts = ReadJsonFile(gt_file);
  if (!cameras.is_object()) ThrowBadValue(camera_file.string(), "not an object", "{\"<im_id>\": {...}}");
  if (!gts.is_object()) ThrowBadValue(gt_file.string(), "not an object", "{\"<im_id>\": [...]}");
  std::optional<nlohmann::json> infos;
  if (fs::exists(info_file)) infos = ReadJsonFile(info_file);

  std::map<int, std::string> ids;  // im_id -> key, sorted by im_id
  for (const auto& [key, value] : cameras.items()) ids[ImageId(key, camera_file)] = key;
  for (const auto& [key, value] : gts.items()) {
    if (!cameras.contains(key)) {
      throw InputError(gt_file.string() + ": image " + key + " has ground truth but no entry in " +
                       camera_file.string() + " (inconsistent ground truth)");
    }
  }
  int width = 0, height = 0;
  for (const auto& [id, key] : ids) {
    const std::string where_camera = camera_file.string() + ": image " + key;
    const nlohmann::json& camera = cameras[key];
    if (!camera.is_object()) ThrowBadValue(where_camera, camera.dump(), "an object");
    if (!camera.contains("depth_scale")) {
      throw InputError(where_camera + ": 'depth_scale' is missing (millimetres per depth unit; "
                       "the depth scale is never assumed)");
    }
    const double depth_scale_mm = Numbers(nlohmann::json{{"d", {camera["depth_scale"]}}}, "d", 1,
                                          where_camera + ": depth_scale")[0];
    if (!(depth_scale_mm > 0)) {
      ThrowBadValue(where_camera + ": depth_scale", FormatNumber(depth_scale_mm),
                    "millimetres per depth unit > 0");
    }
    RecordingFrameInfo info;
    info.image_id = id;
    info.depth_scale = depth_scale_mm / 1000.0;
    info.depth_file = FindImage(folder_, {"depth"}, id);
    if (info.depth_file.empty()) {
      throw InputError((folder_ / "depth").string() + ": no depth image for image " + key +
                       " of " + camera_file.string());
    }
    info.color_file = FindImage(folder_, {"rgb", "gray"}, id);
    if (width == 0) {
      const DepthImage first = ReadDepthPng16(info.depth_file);
      width = first.width;
      height = first.height;
    }
    const std::vector<double> k = Numbers(camera, "cam_K", 9, where_camera);
    info.intrinsics = FromK(k.data(), width, height, where_camera + ": cam_K");
    const std::string where_gt = gt_file.string() + ": image " + key;
    if (!gts.contains(key)) {
      throw InputError(where_gt + " is missing (the image is in " + camera_file.string() +
                       "; inconsistent ground truth)");
    }
    const nlohmann::json& list = gts[key];
    if (!list.is_array()) ThrowBadValue(where_gt, list.dump(), "a list of poses");
    const nlohmann::json* info_list = nullptr;
    if (infos) {
      const std::string where_info = info_file.string() + ": image " + key;
      if (!infos->contains(key)) {
        throw InputError(where_info + " is missing (inconsistent with " + gt_file.string() + ")");
      }
      info_list = &(*infos)[key];
      if (!info_list->is_array() || info_list->size() != list.size()) {
        ThrowBadValue(where_info,
                      std::to_string(info_list->is_array() ? info_list->size() : 0) + " entries",
                      std::to_string(list.size()) + " (one per pose in scene_gt.json)");
      }
    }
    for (size_t j = 0; j < list.size(); ++j) {
      const std::string where = where_gt + ", pose " + std::to_string(j);
      const nlohmann::json& pose = list[j];
      if (!pose.is_object() || !pose.contains("obj_id") || !pose["obj_id"].is_number_integer() ||
          pose["obj_id"].get<int>() < 1) {
        ThrowBadValue(where + ": obj_id", pose.is_object() && pose.contains("obj_id")
                                               ? pose["obj_id"].dump() : "missing",
                      "an integer >= 1");
      }
      const std::vector<double> r = Numbers(pose, "cam_R_m2c", 9, where);
      const std::vector<double> t = Numbers(pose, "cam_t_m2c", 3, where);
      ObjectTruth truth;
      truth.object_id = pose["obj_id"].get<int>();
      truth.camera_T_object = PoseFromRowMajor(r.data(), t.data(), 0.001, where);
      if (info_list) {
        const nlohmann::json& e = (*info_list)[j];
        if (e.is_object() && e.contains("visib_fract") && e["visib_fract"].is_number()) {
          truth.visible_fraction = e["visib_fract"].get<double>();
        }
      }
      info.truth.push_back(truth);
    }
    frames_.push_back(std::move(info));
  }
}

void RecordingFrameSource::ReadYcbVideo() {
  std::vector<std::pair<int, std::string>> stems;
  for (const auto& entry : fs::directory_iterator(folder_)) {
    const std::string name = entry.path().filename().string();
    if (!EndsWith(name, kYcbDepthSuffix)) continue;
    const std::string stem = name.substr(0, name.size() - std::string(kYcbDepthSuffix).size());
    stems.emplace_back(ImageId(stem, entry.path()), stem);
  }
  std::sort(stems.begin(), stems.end());
  int width = 0, height = 0;
  for (const auto& [id, stem] : stems) {
    RecordingFrameInfo info;
    info.image_id = id;
    info.depth_file = folder_ / (stem + kYcbDepthSuffix);
    info.color_file = folder_ / (stem + "-color.png");
    if (!fs::exists(info.color_file)) info.color_file.clear();
    const fs::path mat = folder_ / (stem + "-meta.mat");
    const fs::path text = folder_ / (stem + "-meta.txt");
    fs::path meta_file;
    MatFile meta;
    if (fs::exists(mat)) {
      meta_file = mat;
      meta = ReadMatFile(mat);
    } else if (fs::exists(text)) {
      meta_file = text;
      meta = ReadMatText(text);
    } else {
      throw InputError(info.depth_file.string() + ": no ground truth beside it (" +
                       mat.filename().string() + " or " + text.filename().string() + ")");
    }
    const std::string where = meta_file.string();
    if (width == 0) {
      const DepthImage first = ReadDepthPng16(info.depth_file);
      width = first.width;
      height = first.height;
    }
    const MatArray& k_array = meta.Get("intrinsic_matrix", {3, 3}, meta_file);
    double k[9];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) k[3 * r + c] = k_array.at(r, c);
    }
    info.intrinsics = FromK(k, width, height, where + ": intrinsic_matrix");
    if (!meta.arrays.count("factor_depth")) {
      throw InputError(where + ": variable 'factor_depth' is missing (depth units per metre; the "
                       "depth scale is never assumed)");
    }
    const double factor = meta.Get("factor_depth", {1, 1}, meta_file).values[0];
    if (!(factor > 0) || !std::isfinite(factor)) {
      ThrowBadValue(where + ": factor_depth", FormatNumber(factor), "depth units per metre > 0");
    }
    info.depth_scale = 1.0 / factor;
    const MatArray& classes = meta.Get("cls_indexes", {-1, 1}, meta_file);
    const int64_t n = classes.size();
    const MatArray& poses = meta.Get("poses", {3, 4, n}, meta_file);
    std::set<int> seen;
    for (int64_t j = 0; j < n; ++j) {
      const std::string where_pose = where + ": poses(:, :, " + std::to_string(j + 1) + ")";
      const double c = classes.values[j];
      if (c < 1 || c != std::floor(c)) {
        ThrowBadValue(where + ": cls_indexes(" + std::to_string(j + 1) + ")", FormatNumber(c),
                      "a class index >= 1");
      }
      double r[9], t[3];
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) r[3 * a + b] = poses.at(a, b, j);
        t[a] = poses.at(a, 3, j);
      }
      ObjectTruth truth;
      truth.object_id = static_cast<int>(c);
      truth.camera_T_object = PoseFromRowMajor(r, t, 1.0, where_pose);
      info.truth.push_back(truth);
    }
    frames_.push_back(std::move(info));
  }
}

bool RecordingFrameSource::Next(RgbdFrame* frame) {
  if (next_ >= size()) return false;
  const int k = next_++;
  const RecordingFrameInfo& info = frames_[k];
  *frame = RgbdFrame();
  frame->index = k;
  frame->timestamp = timestamp(k);
  frame->depth_intrinsics = info.intrinsics;
  frame->color_intrinsics = info.intrinsics;
  frame->depth_scale = info.depth_scale;
  frame_error_.clear();
  try {
    DepthImage depth = ReadDepthPng16(info.depth_file);
    if (depth.width != info.intrinsics.width || depth.height != info.intrinsics.height) {
      throw InputError(info.depth_file.string() + ": " + std::to_string(depth.width) + "x" +
                       std::to_string(depth.height) + ", expected " +
                       std::to_string(info.intrinsics.width) + "x" +
                       std::to_string(info.intrinsics.height) + " (the first frame's)");
    }
    frame->depth = std::move(depth.values);
    if (!info.color_file.empty()) {
      RgbImage rgb = ReadRgbImage(info.color_file);
      if (rgb.width == depth.width && rgb.height == depth.height) frame->rgb = std::move(rgb.rgb);
    }
  } catch (const InputError& e) {
    frame->depth.clear();
    frame->rgb.clear();
    frame_error_ = e.what();
  }
  return true;
}

std::string RecordingFrameSource::Describe() const {
  return std::string(RecordingLayoutName(layout_)) + " " + folder_.string();
}

std::vector<int> RecordingFrameSource::object_ids() const {
  std::set<int> ids;
  for (const auto& f : frames_) {
    for (const auto& t : f.truth) ids.insert(t.object_id);
  }
  return {ids.begin(), ids.end()};
}

Trajectory RecordingFrameSource::Truth(int object_id) const {
  Trajectory trajectory;
  for (size_t k = 0; k < frames_.size(); ++k) {
    int count = 0;
    for (const auto& t : frames_[k].truth) {
      if (t.object_id != object_id) continue;
      if (++count > 1) {
        throw InputError(Describe() + ": image " + std::to_string(frames_[k].image_id) +
                         " has two instances of object " + std::to_string(object_id) +
                         " (tracking follows one instance)");
      }
      trajectory.timestamps.push_back(timestamp(static_cast<int>(k)));
      trajectory.poses.push_back(t.camera_T_object);
    }
  }
  return trajectory;
}

}  // namespace mmh::track
