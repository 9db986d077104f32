#include "core/tum_io.h"

#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/error_text.h"
#include "core/resource_limits.h"
#include "core/text_parsing.h"

namespace mmh {

Trajectory ReadTum(const std::filesystem::path& path) {
  Trajectory trajectory;
  ForEachDataRow(
      path, 8, "8 fields: timestamp tx ty tz qx qy qz qw",
      [&](const std::string& where, const std::vector<std::string_view>& fields, int) {
        double v[8];
        static const char* kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
        for (int i = 0; i < 8; ++i) {
          if (!ParseDouble(fields[i], &v[i]) || !std::isfinite(v[i])) {
            ThrowBadValue(where + ", field " + kNames[i], Quote(fields[i]), "a finite number");
          }
          if (i >= 1 && i <= 3 && std::abs(v[i]) > kMaxTranslationMetres) {
            ThrowBadValue(where + ", field " + kNames[i], Quote(fields[i]),
                          "a translation within +-1e6 m (metres; kMaxTranslationMetres)");
          }
        }
        Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
        const double norm = q.norm();
        if (norm < 1e-12) {
          ThrowBadValue(where + ", quaternion", "a zero quaternion", "a unit quaternion");
        }
        if (std::abs(norm - 1.0) > 1e-2) {
          ThrowBadValue(where + ", quaternion norm", FormatNumber(norm),
                        "a unit quaternion (norm within 1 \u00b1 0.01)");
        }
        // Only when needed: normalising a quaternion that is already unit to the last bits would
        // change those bits, and reading then writing a file must give it back unchanged.
        if (std::abs(norm - 1.0) > 1e-12) q.normalize();
        if (!trajectory.timestamps.empty() && !(v[0] > trajectory.timestamps.back())) {
          ThrowBadValue(
              where + ", timestamp", FormatNumber(v[0]),
              "greater than the previous timestamp " + FormatNumber(trajectory.timestamps.back()));
        }
        trajectory.timestamps.push_back(v[0]);
        trajectory.poses.emplace_back(q, Eigen::Vector3d(v[1], v[2], v[3]));
      });
  if (trajectory.empty()) {
    ThrowBadValue(path.string(), "no poses", "at least one line 'timestamp tx ty tz qx qy qz qw'");
  }
  return trajectory;
}

void WriteTum(const std::filesystem::path& path, const Trajectory& trajectory,
              const std::string& comment) {
  ValidateTrajectory(trajectory, path.string());
  if (trajectory.empty()) {
    ThrowBadValue(path.string(), "an empty trajectory", "at least one pose (ReadTum rejects none)");
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    if (!comment.empty()) {
      std::istringstream lines(comment);
      std::string line;
      while (std::getline(lines, line)) out << "# " << line << '\n';
    }
    for (std::size_t i = 0; i < trajectory.size(); ++i) {
      const Rigid3& pose = trajectory.poses[i];
      const auto& t = pose.translation;
      const auto& q = pose.rotation;
      out << FormatNumber(trajectory.timestamps[i]) << ' ' << FormatNumber(t.x()) << ' '
          << FormatNumber(t.y()) << ' ' << FormatNumber(t.z()) << ' ' << FormatNumber(q.x()) << ' '
          << FormatNumber(q.y()) << ' ' << FormatNumber(q.z()) << ' ' << FormatNumber(q.w())
          << '\n';
    }
  });
}

}  // namespace mmh
