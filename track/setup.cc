#include "track/setup.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_text.h"

namespace mmh::track {
namespace {

double Number(const nlohmann::json& object, const std::string& key, const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) ThrowBadValue(where + ": key '" + key + "'", "nothing", "a number");
  if (!it->is_number()) ThrowBadValue(where + ": key '" + key + "'", it->dump(), "a number");
  const double value = it->get<double>();
  RequireFinite(value, where + ": key '" + key + "'");
  return value;
}

Eigen::VectorXd Numbers(const nlohmann::json& object, const std::string& key, int count,
                        const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end() || !it->is_array() || static_cast<int>(it->size()) != count) {
    ThrowBadValue(where + ": key '" + key + "'", it == object.end() ? "nothing" : it->dump(),
                  "an array of " + std::to_string(count) + " numbers");
  }
  Eigen::VectorXd values(count);
  for (int i = 0; i < count; ++i) {
    if (!(*it)[i].is_number()) {
      ThrowBadValue(where + ": key '" + key + "'", it->dump(), "an array of numbers");
    }
    values[i] = (*it)[i].get<double>();
    RequireFinite(values[i], where + ": key '" + key + "'");
  }
  return values;
}

}  // namespace

void TrackSetup::Validate(const std::string& where) const {
  TableSetup::Validate(where);
  if (camera_T_table) {
    RequireFinite(camera_T_table->translation.norm(), where + ".camera_T_table.translation");
    if (std::abs(camera_T_table->rotation.norm() - 1) > 1e-6) {
      ThrowBadValue(where + ".camera_T_table.quaternion_xyzw",
                    FormatNumber(camera_T_table->rotation.norm()), "a unit quaternion (norm 1)");
    }
  }
}

TrackSetup ReadSetupJson(const std::filesystem::path& path) {
  const std::string where = path.string();
  const nlohmann::json root = ReadJsonFile(path);
  if (!root.is_object()) ThrowBadValue(where, root.dump(), "a JSON object");
  TrackSetup setup;
  if (root.contains("camera_T_table")) {
    const nlohmann::json& pose = root["camera_T_table"];
    const std::string pose_where = where + ": camera_T_table";
    if (!pose.is_object()) ThrowBadValue(pose_where, pose.dump(), "an object");
    const Eigen::VectorXd t = Numbers(pose, "translation", 3, pose_where);
    const Eigen::VectorXd q = Numbers(pose, "quaternion_xyzw", 4, pose_where);
    const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
    if (std::abs(rotation.norm() - 1) > 1e-6) {
      ThrowBadValue(pose_where + ".quaternion_xyzw", FormatNumber(rotation.norm()),
                    "a unit quaternion (norm 1 within 1e-6)");
    }
    setup.camera_T_table = Rigid3(rotation.normalized(), Eigen::Vector3d(t[0], t[1], t[2]));
  }
  const auto table = root.find("table");
  if (table == root.end() || !table->is_object()) {
    ThrowBadValue(where + ": key 'table'", table == root.end() ? "nothing" : table->dump(),
                  "an object with the play area and Like box sizes");
  }
  const std::string table_where = where + ": table";
  setup.play_area_width = Number(*table, "play_area_width", table_where);
  setup.play_area_depth = Number(*table, "play_area_depth", table_where);
  setup.like_box_center_x = Number(*table, "like_box_center_x", table_where);
  setup.like_box_center_y = Number(*table, "like_box_center_y", table_where);
  setup.like_box_length = Number(*table, "like_box_length", table_where);
  setup.like_box_width = Number(*table, "like_box_width", table_where);
  if (root.contains("slider_block_size")) {
    setup.slider_block_size = Number(root, "slider_block_size", where);
  }
  setup.Validate(where);
  return setup;
}

}  // namespace mmh::track
