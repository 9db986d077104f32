// The render sections of a config read and checked (sim/render_session.h: RenderConfig and its
// options), apart from the render session so that a program that only reads configs (the light
// mmh: docs/architecture.md, "Start-up") links no renderer (Embree).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "core/error.h"
#include "sim/render_session.h"

namespace mmh::sim {
namespace {

constexpr std::array<std::pair<RenderMode, const char*>, 2> kRenderModeNames = {{
    {RenderMode::kIncremental, "incremental"},
    {RenderMode::kFull, "full"},
}};
constexpr std::array<std::pair<RenderSession, const char*>, 2> kRenderSessionNames = {{
    {RenderSession::kRecording, "recording"},
    {RenderSession::kAnnotation, "annotation"},
}};

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  std::string tail = s.substr(s.size() - suffix.size());
  std::transform(tail.begin(), tail.end(), tail.begin(), ::tolower);
  return tail == suffix;
}

}  // namespace

std::span<const std::pair<RenderMode, const char*>> EnumNames(RenderMode) {
  return kRenderModeNames;
}
std::span<const std::pair<RenderSession, const char*>> EnumNames(RenderSession) {
  return kRenderSessionNames;
}

void CameraPlacement::Validate(const std::string& prefix) const {
  for (auto [name, value] : {std::pair{"x", x},
                             {"y", y},
                             {"z", z},
                             {"look_at_x", look_at_x},
                             {"look_at_y", look_at_y},
                             {"look_at_z", look_at_z}}) {
    RequireFinite(value, prefix + "." + name);
  }
  const Eigen::Vector3d forward(look_at_x - x, look_at_y - y, look_at_z - z);
  if (forward.norm() < 0.1) {
    ThrowBadValue(prefix + ".look_at", "a point " + FormatNumber(forward.norm()) + " m away",
                  "a point at least 0.1 m from the camera");
  }
  if (!std::isfinite(roll_deg) || std::abs(roll_deg) > 180.0) {
    ThrowBadValue(prefix + ".roll_deg", FormatNumber(roll_deg),
                  "a turn about the viewing axis in [-180, 180] degrees");
  }
  if (forward.normalized().cross(Eigen::Vector3d::UnitZ()).norm() < 1e-3) {
    ThrowBadValue(prefix + ".look_at", "straight up or down",
                  "a viewing direction that is not vertical (the image x axis is kept "
                  "horizontal)");
  }
}

Rigid3 CameraPlacement::TableTCamera() const {
  const Eigen::Vector3d position(x, y, z);
  const Eigen::Vector3d forward =
      (Eigen::Vector3d(look_at_x, look_at_y, look_at_z) - position).normalized();
  // x right (horizontal), y down in the image, z forward.
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d r;
  r.col(0) = right;
  r.col(1) = down;
  r.col(2) = forward;
  if (roll_deg != 0) {
    // x' = cos(roll) right + sin(roll) down: the image turned about the viewing axis.
    r = r * Eigen::AngleAxisd(roll_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ())
                .toRotationMatrix();
  }
  return Rigid3(Eigen::Quaterniond(r).normalized(), position);
}

void DemoMotionOptions::Validate(const std::string& prefix) const {
  RequirePositive(radius_x, prefix + ".radius_x", "m");
  RequirePositive(radius_y, prefix + ".radius_y", "m");
  RequirePositive(round_period, prefix + ".round_period", "s");
  RequirePositive(step_rate, prefix + ".step_rate", "steps/s");
  if (!std::isfinite(bounce_height) || bounce_height < 0 || bounce_height > 0.2) {
    ThrowBadValue(prefix + ".bounce_height", FormatNumber(bounce_height), "a height in [0, 0.2] m");
  }
  if (!std::isfinite(yaw_swing) || std::abs(yaw_swing) > std::numbers::pi) {
    ThrowBadValue(prefix + ".yaw_swing", FormatNumber(yaw_swing), "an angle in [-pi, pi] rad");
  }
  RequirePositive(slider_period, prefix + ".slider_period", "s");
}

Rigid3 DemoMotionOptions::TableTProxy(double t) const {
  const double w = 2 * std::numbers::pi / round_period;
  const Eigen::Vector3d position(
      radius_x * std::cos(w * t), radius_y * std::sin(w * t),
      bounce_height * std::abs(std::sin(std::numbers::pi * step_rate * t)));
  // Heading along the path (the figure faces where it walks: its -y side is its front), plus a
  // swing like a head turn.
  const double heading = std::atan2(radius_y * std::cos(w * t), -radius_x * std::sin(w * t));
  const double yaw =
      heading + std::numbers::pi / 2 + yaw_swing * std::sin(2 * std::numbers::pi * 0.4 * t);
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), position);
}

double DemoMotionOptions::SliderValue(double t) const {
  return 5.0 * std::sin(2 * std::numbers::pi * t / slider_period);
}

void RenderOptions::Validate(const std::string& prefix) const {
  if (frames < 0 || frames > 1000000) {
    ThrowBadValue(prefix + ".frames", std::to_string(frames),
                  "a frame count in [1, 1000000], or 0 for the whole take");
  }
  if (take < 0 || take > 100000) {
    ThrowBadValue(prefix + ".take", std::to_string(take), "an index in [0, 100000]");
  }
  if (png_compression < 0 || png_compression > 9) {
    ThrowBadValue(prefix + ".png_compression", std::to_string(png_compression),
                  "a zlib level in [0, 9]");
  }
  RequirePositive(proxy_scale, prefix + ".proxy_scale");
  if (!proxy.empty() && !EndsWith(proxy, ".json") && !EndsWith(proxy, ".obj") &&
      !EndsWith(proxy, ".ply")) {
    ThrowBadValue(prefix + ".proxy", "\"" + proxy + "\"",
                  "a Duplo assembly (.json) or a mesh (.obj, .ply), or empty for the Soldier");
  }
}

RenderConfig RenderConfig::FromConfig(const Config& config) {
  config.RequireOnlySections({"render", "camera", "scene", "hand", "sensor", "motion", "scenario", "population",
                              "performance", "annotator", "viewer", "self_appraisal", "study", "scorers", "montage",
                              "track", "metrics", "run", "tracker", "slider", "error_model"});
  RenderConfig c;
  c.render = config.Get<RenderOptions>("render");
  c.camera = config.Get<CameraPlacement>("camera");
  c.scene = config.Get<TableSceneOptions>("scene");
  // A config file names its objects' meshes relative to itself (a view file beside its models).
  const std::filesystem::path folder = config.FolderOf("scene.objects");
  for (SceneObject& o : c.scene.objects) {
    if (!folder.empty() && std::filesystem::path(o.mesh).is_relative()) {
      o.mesh = (folder / o.mesh).lexically_normal().string();
    }
  }
  c.hand = config.Get<HandOptions>("hand");
  c.sensor = config.Get<KinectSensorOptions>("sensor");
  c.motion = config.Get<DemoMotionOptions>("motion");
  return c;
}

nlohmann::json RenderConfig::ToJson() const {
  nlohmann::json j;
  j["render"] = mmh::ToJson(render);
  j["camera"] = mmh::ToJson(camera);
  j["scene"] = mmh::ToJson(scene);
  j["hand"] = mmh::ToJson(hand);
  j["sensor"] = mmh::ToJson(sensor);
  j["motion"] = mmh::ToJson(motion);
  return j;
}

}  // namespace mmh::sim
