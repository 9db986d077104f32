#include "core/rgbd_folder.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <set>
#include <sstream>
#include <system_error>
#include <tuple>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/error_text.h"
#include "core/image_io.h"
#include "core/json_text.h"
#include "core/options.h"
#include "core/text_parsing.h"
#include "core/tum_io.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCameraFile = "camera.json";

// TUM RGB-D file names and list entries: seconds with 6 decimals.
std::string FormatTimestamp(double seconds) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.6f", seconds);
  return buffer;
}

std::string Lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

nlohmann::json PoseToJson(const Rigid3& pose) {
  const auto& t = pose.translation;
  const auto& q = pose.rotation;
  return {{"translation", {t.x(), t.y(), t.z()}}, {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

// Reads an array of `n` finite numbers at json[key]; InputError naming where otherwise.
std::vector<double> ReadNumbers(const nlohmann::json& json, const std::string& key, size_t n,
                                const std::string& where) {
  const auto it = json.find(key);
  bool ok = it != json.end() && it->is_array() && it->size() == n;
  std::vector<double> values;
  if (ok) {
    for (const auto& v : *it) {
      ok = ok && v.is_number() && std::isfinite(v.get<double>());
      if (ok) values.push_back(v.get<double>());
    }
  }
  if (!ok) {
    ThrowBadValue(where + "." + key, it == json.end() ? "nothing" : it->dump(),
                  "an array of " + std::to_string(n) + " finite numbers");
  }
  return values;
}

Rigid3 PoseFromJson(const nlohmann::json& json, const std::string& where) {
  if (!json.is_object())
    ThrowBadValue(where, json.dump(), "an object {translation, rotation_xyzw}");
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (it.key() != "translation" && it.key() != "rotation_xyzw") {
      ThrowBadValue(where, "the unknown key '" + it.key() + "'",
                    "only the keys translation, rotation_xyzw");
    }
  }
  const auto t = ReadNumbers(json, "translation", 3, where);
  const auto q = ReadNumbers(json, "rotation_xyzw", 4, where);
  return Rigid3(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), Eigen::Vector3d(t[0], t[1], t[2]));
}

PinholeIntrinsics IntrinsicsFromJson(const nlohmann::json& json, const std::string& key,
                                     const fs::path& path) {
  const std::string where = path.string() + ": " + key;
  if (!json.is_object()) ThrowBadValue(where, json.dump(), "an object of intrinsics");
  PinholeIntrinsics intrinsics;
  // Every field is required: a default focal length would silently give wrong geometry.
  for (const char* name : {"width", "height", "fx", "fy", "cx", "cy"}) {
    if (!json.contains(name)) {
      ThrowBadValue(where, "no '" + std::string(name) + "'", "width, height, fx, fy, cx and cy");
    }
  }
  FromJson(json, key, ConfigSource{path.string()}, &intrinsics);
  intrinsics.Validate(where);
  return intrinsics;
}

// camera.json -> camera info; `extra` receives the "extra" object.
RgbdCameraInfo CameraInfoFromJson(const fs::path& path, nlohmann::json* extra) {
  const nlohmann::json json = ReadJsonFile(path);
  if (!json.is_object()) ThrowBadValue(path.string(), Quote(json.dump()), "a JSON object");
  static const char* kKnown[] = {"writer",        "format",           "frames",
                                 "depth_scale",   "depth_intrinsics", "color_intrinsics",
                                 "color_T_depth", "sensor",           "extra"};
  for (auto it = json.begin(); it != json.end(); ++it) {
    if (std::find_if(std::begin(kKnown), std::end(kKnown),
                     [&](const char* k) { return it.key() == k; }) == std::end(kKnown)) {
      ThrowBadValue(path.string(), "the unknown key '" + it.key() + "'",
                    "only writer, format, frames, depth_scale, depth_intrinsics, "
                    "color_intrinsics, color_T_depth, sensor, extra");
    }
  }
  RgbdCameraInfo camera;
  if (!json.contains("depth_intrinsics")) {
    ThrowBadValue(path.string(), "no depth_intrinsics",
                  "depth_intrinsics {width, height, fx, fy, cx, cy}");
  }
  camera.depth_intrinsics = IntrinsicsFromJson(json["depth_intrinsics"], "depth_intrinsics", path);
  camera.color_intrinsics =
      json.contains("color_intrinsics")
          ? IntrinsicsFromJson(json["color_intrinsics"], "color_intrinsics", path)
          : camera.depth_intrinsics;
  if (json.contains("depth_scale")) {
    const auto& scale = json["depth_scale"];
    if (!scale.is_number() || !std::isfinite(scale.get<double>()) || scale.get<double>() <= 0) {
      ThrowBadValue(path.string() + ": depth_scale", scale.dump(),
                    "a finite number > 0 (metres per depth unit; TUM: 0.0002)");
    }
    camera.depth_scale = scale.get<double>();
  }
  if (json.contains("color_T_depth")) {
    camera.color_T_depth = PoseFromJson(json["color_T_depth"], path.string() + ": color_T_depth");
  }
  if (json.contains("sensor")) camera.sensor = json["sensor"];
  if (json.contains("extra")) *extra = json["extra"];
  camera.Validate(path.string());
  return camera;
}

struct ListEntry {
  double timestamp;
  fs::path file;  // relative to the folder
  int line;
};

// A TUM list file: '#' comments, then 'timestamp filename' per line.
std::vector<ListEntry> ReadList(const fs::path& path) {
  std::vector<ListEntry> entries;
  ForEachDataRow(
      path, 2, "2 fields: timestamp filename",
      [&](const std::string& where, const std::vector<std::string_view>& fields, int line_number) {
        double timestamp = 0;
        if (!ParseDouble(fields[0], &timestamp) || !std::isfinite(timestamp)) {
          ThrowBadValue(where + ", timestamp", "'" + std::string(fields[0]) + "'",
                        "a finite number of seconds");
        }
        entries.push_back({timestamp, fs::path(std::string(fields[1])), line_number});
      });
  if (entries.empty()) {
    ThrowBadValue(path.string(), "no entries", "at least one line 'timestamp filename'");
  }
  return entries;
}

}  // namespace

void RgbdCameraInfo::Validate(const std::string& prefix) const {
  if (png_compression < 0 || png_compression > 9) {
    ThrowBadValue(prefix + ": png_compression", std::to_string(png_compression),
                  "a zlib level in [0, 9]");
  }
  depth_intrinsics.Validate(prefix + ": depth_intrinsics");
  color_intrinsics.Validate(prefix + ": color_intrinsics");
  if (!std::isfinite(depth_scale) || depth_scale <= 0) {
    ThrowBadValue(prefix + ": depth_scale", FormatNumber(depth_scale),
                  "a finite number > 0 (metres per depth unit; TUM: 0.0002)");
  }
  const double norm = color_T_depth.rotation.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6) {
    ThrowBadValue(prefix + ": color_T_depth.rotation_xyzw norm", FormatNumber(norm),
                  "a unit quaternion");
  }
  if (!color_T_depth.translation.allFinite()) {
    ThrowBadValue(prefix + ": color_T_depth.translation", "a non-finite value", "finite metres");
  }
  if (!sensor.is_object() && !sensor.is_null()) {
    ThrowBadValue(prefix + ": sensor", sensor.dump(), "a JSON object or null");
  }
}

std::optional<RgbdCameraInfo> TumCameraInfoFromName(const std::string& folder_name) {
  struct Calibration {
    const char* name;
    double fx, fy, cx, cy;
  };
  // TUM RGB-D benchmark, "File Formats": the ROS-calibrated colour cameras of the three Kinects;
  // depth is registered to colour.
  static constexpr Calibration kTum[] = {{"freiburg1", 517.3, 516.5, 318.6, 255.3},
                                         {"freiburg2", 520.9, 521.0, 325.1, 249.7},
                                         {"freiburg3", 535.4, 539.2, 320.1, 247.6}};
  const std::string name = Lowercase(folder_name);
  for (const auto& c : kTum) {
    if (name.find(c.name) == std::string::npos) continue;
    RgbdCameraInfo camera;
    camera.depth_intrinsics = {640, 480, c.fx, c.fy, c.cx, c.cy};
    camera.color_intrinsics = camera.depth_intrinsics;
    camera.depth_scale = kTumDepthScale;
    camera.sensor = {{"dataset", "TUM RGB-D"}, {"calibration", c.name}};
    return camera;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Writer

struct RgbdFolderWriter::Shared {
  std::mutex mutex;
  std::set<std::string> names;
  std::vector<std::pair<double, std::string>> entries;  // (timestamp, "<timestamp>.png")
};

RgbdFolderWriter::RgbdFolderWriter(const fs::path& target, const RgbdCameraInfo& camera)
    : folder_(target), camera_(camera), shared_(new Shared) {
  camera_.Validate(folder_.target().string() + " (camera info)");
  EnsureDirectory(staging() / "rgb");
  EnsureDirectory(staging() / "depth");
}

RgbdFolderWriter::~RgbdFolderWriter() = default;

void RgbdFolderWriter::Add(const RgbdFrame& frame) {
  const std::string where = target().string() + ", frame " + std::to_string(frame.index);
  if (folder_.committed()) ThrowBadValue(where, "a frame after Finish()", "frames before Finish()");
  const PinholeIntrinsics& di = camera_.depth_intrinsics;
  const PinholeIntrinsics& ci = camera_.color_intrinsics;
  if (frame.depth.size() != static_cast<size_t>(di.pixel_count())) {
    ThrowBadValue(where + ", depth", std::to_string(frame.depth.size()) + " pixels",
                  std::to_string(di.pixel_count()) + " = " + std::to_string(di.width) + "x" +
                      std::to_string(di.height) + " (camera info)");
  }
  if (frame.rgb.size() != static_cast<size_t>(ci.pixel_count()) * 3) {
    ThrowBadValue(where + ", rgb", std::to_string(frame.rgb.size()) + " bytes",
                  std::to_string(ci.pixel_count() * 3) + " = " + std::to_string(ci.width) + "x" +
                      std::to_string(ci.height) + "x3 (camera info)");
  }
  if (!(frame.depth_intrinsics == di) || !(frame.color_intrinsics == ci)) {
    ThrowBadValue(where, "intrinsics that differ from the camera info",
                  "the intrinsics the writer was made with (camera.json holds one set)");
  }
  if (frame.depth_scale != camera_.depth_scale) {
    ThrowBadValue(where + ", depth_scale", FormatNumber(frame.depth_scale),
                  FormatNumber(camera_.depth_scale) + " (camera info)");
  }
  if (!std::isfinite(frame.timestamp) || frame.timestamp < 0) {
    ThrowBadValue(where + ", timestamp", FormatNumber(frame.timestamp), "finite seconds >= 0");
  }
  const std::string name = FormatTimestamp(frame.timestamp) + ".png";
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    if (!shared_->names.insert(name).second) {
      ThrowBadValue(where + ", timestamp", FormatNumber(frame.timestamp),
                    "a timestamp that differs from every other frame's at 6 decimals (" + name +
                        " is taken)");
    }
  }
  WriteDepthPng16(staging() / "depth" / name, DepthImage{di.width, di.height, frame.depth},
                  camera_.png_compression);
  WriteRgbPng(staging() / "rgb" / name, RgbImage{ci.width, ci.height, frame.rgb},
              camera_.png_compression);
  std::lock_guard<std::mutex> lock(shared_->mutex);
  shared_->entries.emplace_back(frame.timestamp, name);
}

std::vector<std::pair<fs::path, fs::path>> RgbdFolderWriter::AddedImages() const {
  std::vector<std::pair<double, std::string>> entries;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    entries = shared_->entries;
  }
  std::sort(entries.begin(), entries.end());
  std::vector<std::pair<fs::path, fs::path>> images;
  images.reserve(entries.size());
  for (const auto& [timestamp, name] : entries) {
    images.emplace_back(fs::path("depth") / name, fs::path("rgb") / name);
  }
  return images;
}

void RgbdFolderWriter::Finish(const std::optional<Trajectory>& groundtruth,
                              const nlohmann::json& extra) {
  if (folder_.committed()) {
    ThrowBadValue(target().string(), "a second Finish()", "one Finish() per writer");
  }
  std::vector<std::pair<double, std::string>> entries;
  {
    std::lock_guard<std::mutex> lock(shared_->mutex);
    entries = shared_->entries;
  }
  if (entries.empty()) ThrowBadValue(target().string(), "no frames", "at least one added frame");
  std::sort(entries.begin(), entries.end());
  auto write_list = [&](const char* folder, const char* title) {
    WriteFileAtomically(staging() / (std::string(folder) + ".txt"), [&](std::ostream& out) {
      out << "# " << title << "\n# written by mmh\n# timestamp filename\n";
      for (const auto& [timestamp, name] : entries) {
        out << FormatTimestamp(timestamp) << ' ' << folder << '/' << name << '\n';
      }
    });
  };
  write_list("rgb", "color images");
  write_list("depth", "depth maps");
  if (groundtruth) {
    WriteTum(staging() / "groundtruth.txt", *groundtruth,
             "ground truth trajectory (camera_T_proxy)\ntimestamp tx ty tz qx qy qz qw");
  }
  const nlohmann::json json = {{"writer", kMmhWriterName},
                               {"format", "tum-rgbd"},
                               {"frames", entries.size()},
                               {"depth_scale", camera_.depth_scale},
                               {"depth_intrinsics", ToJson(camera_.depth_intrinsics)},
                               {"color_intrinsics", ToJson(camera_.color_intrinsics)},
                               {"color_T_depth", PoseToJson(camera_.color_T_depth)},
                               {"sensor", camera_.sensor},
                               {"extra", extra}};
  WriteFileAtomically(staging() / kCameraFile, json.dump(2) + "\n");
  folder_.Commit();
}

// ---------------------------------------------------------------------------------------------
// Reader

std::vector<std::pair<int, int>> AssociateTimestamps(const std::vector<double>& rgb,
                                                     const std::vector<double>& depth,
                                                     double max_difference) {
  // Depth indices sorted by time, to find each rgb entry's candidates by binary search.
  std::vector<int> by_time(depth.size());
  for (size_t j = 0; j < depth.size(); ++j) by_time[j] = static_cast<int>(j);
  std::sort(by_time.begin(), by_time.end(),
            [&](int a, int b) { return std::tie(depth[a], a) < std::tie(depth[b], b); });
  std::vector<std::tuple<double, int, int>> candidates;  // (|difference|, rgb, depth)
  for (size_t i = 0; i < rgb.size(); ++i) {
    auto it = std::lower_bound(by_time.begin(), by_time.end(), rgb[i] - max_difference,
                               [&](int j, double t) { return depth[j] < t; });
    for (; it != by_time.end() && depth[*it] <= rgb[i] + max_difference; ++it) {
      const double difference = std::abs(rgb[i] - depth[*it]);
      if (difference < max_difference) candidates.emplace_back(difference, i, *it);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> rgb_used(rgb.size()), depth_used(depth.size());
  std::vector<std::pair<int, int>> matches;
  for (const auto& [difference, i, j] : candidates) {
    if (rgb_used[i] || depth_used[j]) continue;
    rgb_used[i] = depth_used[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end(), [&](const auto& a, const auto& b) {
    return std::tie(rgb[a.first], depth[a.second], a.first) <
           std::tie(rgb[b.first], depth[b.second], b.first);
  });
  return matches;
}

RgbdFolderReader::RgbdFolderReader(const fs::path& folder,
                                   const std::optional<PinholeIntrinsics>& intrinsics)
    : folder_(WithoutTrailingSeparator(folder)) {
  std::error_code ec;
  if (!fs::is_directory(folder_, ec)) {
    ThrowBadValue(folder_.string(),
                  fs::exists(folder_, ec) ? "a file" : "a path that does not exist",
                  "an RGB-D folder (TUM RGB-D layout: rgb.txt, depth.txt, rgb/, depth/)");
  }
  const fs::path camera_file = folder_ / kCameraFile;
  if (fs::exists(camera_file, ec)) {
    camera_ = CameraInfoFromJson(camera_file, &extra_);
  } else if (auto tum = TumCameraInfoFromName(folder_.filename().string())) {
    camera_ = *tum;
  } else if (!intrinsics) {
    ThrowBadValue(folder_.string(),
                  "no camera.json and a folder name without 'freiburg1', 'freiburg2' or "
                  "'freiburg3'",
                  "camera.json, explicit intrinsics, or a TUM RGB-D sequence name");
  }
  if (intrinsics) {
    intrinsics->Validate(folder_.string() + " (explicit intrinsics)");
    camera_.depth_intrinsics = *intrinsics;
    camera_.color_intrinsics = *intrinsics;
  }

  const std::vector<ListEntry> rgb = ReadList(folder_ / "rgb.txt");
  const std::vector<ListEntry> depth = ReadList(folder_ / "depth.txt");
  std::vector<double> rgb_times, depth_times;
  for (const auto& e : rgb) rgb_times.push_back(e.timestamp);
  for (const auto& e : depth) depth_times.push_back(e.timestamp);
  const auto matches = AssociateTimestamps(rgb_times, depth_times, kRgbdMaxTimeDifference);
  if (matches.empty()) {
    ThrowBadValue(folder_.string(), "no rgb.txt and depth.txt entries within 0.02 s of each other",
                  "associated colour and depth images");
  }
  auto require_file = [&](const ListEntry& entry, const char* list) {
    const fs::path file = folder_ / entry.file;
    if (!fs::is_regular_file(file, ec)) {
      ThrowBadValue(folder_.string() + "/" + list + ":" + std::to_string(entry.line),
                    "'" + entry.file.string() + "', which does not exist",
                    "an existing image file");
    }
    return file;
  };
  for (const auto& [i, j] : matches) {
    pairs_.push_back({rgb[i].timestamp, require_file(rgb[i], "rgb.txt"), depth[j].timestamp,
                      require_file(depth[j], "depth.txt")});
  }
}

RgbdFrame RgbdFolderReader::Read(int i) const {
  const Pair& pair = pairs_.at(static_cast<size_t>(i));
  RgbdFrame frame;
  frame.index = i;
  frame.timestamp = pair.depth_timestamp;
  frame.depth_scale = camera_.depth_scale;
  frame.depth_intrinsics = camera_.depth_intrinsics;
  frame.color_intrinsics = camera_.color_intrinsics;
  frame.color_T_depth = camera_.color_T_depth;
  auto require_size = [](const fs::path& file, int width, int height,
                         const PinholeIntrinsics& expected, const char* which) {
    if (width != expected.width || height != expected.height) {
      ThrowBadValue(file.string(),
                    "an image of " + std::to_string(width) + "x" + std::to_string(height) + " px",
                    std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                        " px (the " + which + " intrinsics)");
    }
  };
  DepthImage depth = ReadDepthPng16(pair.depth_file);
  require_size(pair.depth_file, depth.width, depth.height, camera_.depth_intrinsics, "depth");
  frame.depth = std::move(depth.values);
  RgbImage rgb = ReadRgbImage(pair.rgb_file);
  require_size(pair.rgb_file, rgb.width, rgb.height, camera_.color_intrinsics, "colour");
  frame.rgb = std::move(rgb.rgb);
  return frame;
}

std::optional<Trajectory> RgbdFolderReader::ReadGroundtruth() const {
  const fs::path path = folder_ / "groundtruth.txt";
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  return ReadTum(path);
}

}  // namespace mmh
