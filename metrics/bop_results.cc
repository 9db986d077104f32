#include "metrics/bop_results.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/error.h"
#include "core/text_parsing.h"

namespace mmh::metrics {
namespace {

constexpr char kHeader[] = "scene_id,im_id,obj_id,score,R,t,time";

// The numbers of a space-separated field (`count` of them) or an InputError naming `where`.
std::vector<double> Numbers(std::string_view field, size_t count, const std::string& where) {
  std::vector<double> numbers;
  for (std::string_view word : SplitFields(field, " \t")) {
    double value = 0;
    if (!ParseDouble(word, &value) || !std::isfinite(value)) {
      ThrowBadValue(where, "\"" + std::string(field) + "\"",
                    std::to_string(count) + " finite numbers");
    }
    numbers.push_back(value);
  }
  if (numbers.size() != count) {
    ThrowBadValue(where, "\"" + std::string(field) + "\"", std::to_string(count) + " numbers");
  }
  return numbers;
}

int Id(std::string_view field, const std::string& where) {
  const double value = Numbers(field, 1, where)[0];
  if (value != std::floor(value) || value < 0 || value > 1e9) {
    ThrowBadValue(where, "\"" + std::string(field) + "\"", "a non-negative integer");
  }
  return static_cast<int>(value);
}

}  // namespace

std::vector<BopResult> ReadBopResults(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  std::vector<BopResult> results;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line.rfind("scene_id", 0) == 0) continue;
    const std::string where = path.string() + ":" + std::to_string(number);
    const std::vector<std::string_view> fields = SplitCsvFields(line);
    if (fields.size() != 7) {
      throw InputError(where + ": " + std::to_string(fields.size()) + " fields, expected 7 (" +
                       kHeader + ")");
    }
    BopResult r;
    r.scene_id = Id(fields[0], where + ": scene_id");
    r.im_id = Id(fields[1], where + ": im_id");
    r.obj_id = Id(fields[2], where + ": obj_id");
    r.score = Numbers(fields[3], 1, where + ": score")[0];
    const std::vector<double> m = Numbers(fields[4], 9, where + ": R");
    const std::vector<double> t = Numbers(fields[5], 3, where + ": t");
    r.time = Numbers(fields[6], 1, where + ": time")[0];
    Eigen::Matrix3d rotation;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation(i, j) = m[3 * i + j];
    }
    if ((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
            1e-3 ||
        std::abs(rotation.determinant() - 1) > 1e-3) {
      ThrowBadValue(where + ": R", "\"" + std::string(fields[4]) + "\"",
                    "a rotation matrix, row-major");
    }
    r.camera_T_object = Rigid3(Eigen::Quaterniond(rotation).normalized(),
                               0.001 * Eigen::Vector3d(t[0], t[1], t[2]));
    results.push_back(r);
  }
  return results;
}

std::optional<int> SceneIdOfFolder(const std::filesystem::path& folder) {
  std::filesystem::path normal = folder.lexically_normal();
  if (normal.filename().empty()) normal = normal.parent_path();  // "scene/"
  const std::string name = normal.filename().string();
  if (name.empty() || name.size() > 9 ||
      !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  return std::stoi(name);
}

std::string FormatBopResults(const std::vector<BopResult>& results) {
  std::ostringstream out;
  out << kHeader << '\n';
  for (const BopResult& r : results) {
    const Eigen::Matrix3d rotation = r.camera_T_object.rotation.toRotationMatrix();
    out << r.scene_id << ',' << r.im_id << ',' << r.obj_id << ',' << std::setprecision(9)
        << r.score << ',';
    for (int i = 0; i < 9; ++i) out << (i ? " " : "") << rotation(i / 3, i % 3);
    out << ',' << std::fixed << std::setprecision(6);
    for (int i = 0; i < 3; ++i) out << (i ? " " : "") << 1000 * r.camera_T_object.translation[i];
    out << ',' << std::defaultfloat << std::setprecision(9) << r.time << '\n';
  }
  return out.str();
}

}  // namespace mmh::metrics
