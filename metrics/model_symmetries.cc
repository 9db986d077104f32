#include "metrics/model_symmetries.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "core/json_text.h"

namespace mmh::metrics {
namespace {

// The numbers of `value` (an array of `count` finite numbers) or an InputError naming `where`.
std::vector<double> Numbers(const nlohmann::json& value, size_t count, const std::string& where) {
  if (!value.is_array() || value.size() != count) {
    ThrowBadValue(where, value.dump(), "an array of " + std::to_string(count) + " numbers");
  }
  std::vector<double> numbers;
  for (const auto& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      ThrowBadValue(where, value.dump(), "an array of " + std::to_string(count) + " finite numbers");
    }
    numbers.push_back(v.get<double>());
  }
  return numbers;
}

Rigid3 DiscreteSymmetry(const nlohmann::json& value, double scale, const std::string& where) {
  const std::vector<double> m = Numbers(value, 16, where);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = m[4 * i + j];
  }
  const bool rotation = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <=
                            1e-3 &&
                        std::abs(r.determinant() - 1) <= 1e-3;
  const bool last_row = m[12] == 0 && m[13] == 0 && m[14] == 0 && m[15] == 1;
  if (!rotation || !last_row) {
    ThrowBadValue(where, value.dump(),
                  "a 4x4 rigid transformation, row-major (a rotation, last row 0 0 0 1)");
  }
  return Rigid3(Eigen::Quaterniond(r).normalized(),
                scale * Eigen::Vector3d(m[3], m[7], m[11]));
}

}  // namespace

std::map<int, ModelSymmetries> ReadModelsInfo(const std::filesystem::path& path, double scale) {
  const nlohmann::json json = ReadJsonFile(path);
  const std::string file = path.string();
  if (!json.is_object()) {
    throw InputError(file + ": expected an object {\"<obj_id>\": {...}} (BOP models_info.json)");
  }
  std::map<int, ModelSymmetries> objects;
  for (const auto& [key, info] : json.items()) {
    const std::string where = file + ": object \"" + key + "\"";
    int id = 0;
    try {
      size_t used = 0;
      id = std::stoi(key, &used);
      if (used != key.size()) throw std::invalid_argument(key);
    } catch (const std::exception&) {
      throw InputError(where + ": the key is not an integer object id");
    }
    if (!info.is_object()) throw InputError(where + ": expected an object");
    ModelSymmetries& s = objects[id];
    if (info.contains("symmetries_discrete")) {
      const auto& list = info["symmetries_discrete"];
      if (!list.is_array()) ThrowBadValue(where + ".symmetries_discrete", list.dump(), "an array");
      for (size_t i = 0; i < list.size(); ++i) {
        s.discrete.push_back(DiscreteSymmetry(
            list[i], scale, where + ".symmetries_discrete[" + std::to_string(i) + "]"));
      }
    }
    if (info.contains("symmetries_continuous")) {
      const auto& list = info["symmetries_continuous"];
      if (!list.is_array()) ThrowBadValue(where + ".symmetries_continuous", list.dump(), "an array");
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string at = where + ".symmetries_continuous[" + std::to_string(i) + "]";
        if (!list[i].is_object() || !list[i].contains("axis") || !list[i].contains("offset")) {
          ThrowBadValue(at, list[i].dump(), "{\"axis\": [3], \"offset\": [3]}");
        }
        const std::vector<double> a = Numbers(list[i]["axis"], 3, at + ".axis");
        const std::vector<double> o = Numbers(list[i]["offset"], 3, at + ".offset");
        ContinuousSymmetry c;
        c.axis = Eigen::Vector3d(a[0], a[1], a[2]);
        if (c.axis.norm() < 1e-9) ThrowBadValue(at + ".axis", list[i]["axis"].dump(), "non-zero");
        c.axis.normalize();
        c.offset = scale * Eigen::Vector3d(o[0], o[1], o[2]);
        s.continuous.push_back(c);
      }
    }
  }
  return objects;
}

std::vector<Rigid3> SymmetryTransformations(const ModelSymmetries& symmetries, double max_step) {
  if (!(max_step > 0)) ThrowBadValue("max_step", FormatNumber(max_step), "> 0");
  std::vector<Rigid3> discrete = {Rigid3()};
  discrete.insert(discrete.end(), symmetries.discrete.begin(), symmetries.discrete.end());
  if (symmetries.continuous.empty()) return discrete;
  // A full turn in n steps moves the point furthest from the axis (at most a radius, half a
  // diameter, away) by at most pi * diameter / n between steps: n = ceil(pi / max_step) keeps
  // that within max_step diameters.
  const int steps = static_cast<int>(std::ceil(std::numbers::pi / max_step));
  std::vector<Rigid3> turns;
  for (const ContinuousSymmetry& c : symmetries.continuous) {
    for (int k = 0; k < steps; ++k) {
      const Eigen::Quaterniond r(Eigen::AngleAxisd(2 * std::numbers::pi * k / steps, c.axis));
      turns.emplace_back(r, c.offset - r * c.offset);
    }
  }
  std::vector<Rigid3> all;
  for (const Rigid3& d : discrete) {
    for (const Rigid3& turn : turns) all.push_back(turn * d);
  }
  return all;
}

}  // namespace mmh::metrics
