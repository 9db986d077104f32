#include "sim/render_session.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "sim/bop_writer.h"
#include "sim/duplo.h"
#include "sim/fakenect_writer.h"

namespace mmh::sim {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::array<std::pair<RenderMode, const char*>, 2> kRenderModeNames = {{
    {RenderMode::kIncremental, "incremental"},
    {RenderMode::kFull, "full"},
}};

Eigen::Quaterniond Yaw(double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
}

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
  return Rigid3(Yaw(yaw), position);
}

double DemoMotionOptions::SliderValue(double t) const {
  return 5.0 * std::sin(2 * std::numbers::pi * t / slider_period);
}

void RenderOptions::Validate(const std::string& prefix) const {
  if (frames < 1 || frames > 1000000) {
    ThrowBadValue(prefix + ".frames", std::to_string(frames), "a frame count in [1, 1000000]");
  }
  RequirePositive(proxy_scale, prefix + ".proxy_scale");
  if (!proxy.empty() && !EndsWith(proxy, ".json") && !EndsWith(proxy, ".obj") &&
      !EndsWith(proxy, ".ply")) {
    ThrowBadValue(prefix + ".proxy", "\"" + proxy + "\"",
                  "a Duplo assembly (.json) or a mesh (.obj, .ply), or empty for the Soldier");
  }
}

RenderConfig RenderConfig::FromConfig(const Config& config) {
  config.RequireOnlySections({"render", "camera", "scene", "hand", "sensor", "motion"});
  RenderConfig c;
  c.render = config.Get<RenderOptions>("render");
  c.camera = config.Get<CameraPlacement>("camera");
  c.scene = config.Get<TableSceneOptions>("scene");
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

TriangleMesh LoadProxyModel(const std::string& proxy, double scale) {
  if (proxy.empty()) return BuildDuploMesh(SoldierProxy());
  if (EndsWith(proxy, ".json")) return BuildDuploMesh(LoadDuploAssembly(proxy));
  return LoadMesh(proxy, scale);
}

TableTopScene::TableTopScene(const RenderConfig& config, const TriangleMesh& proxy_model)
    : config_(config), table_T_camera_(config.camera.TableTCamera()) {
  for (const NamedMesh& part : BuildTableScene(config.scene)) {
    scene_.AddStatic(part.name, part.mesh, Rigid3::Identity());
  }
  proxy_ = scene_.AddMoving("proxy", proxy_model);
  const Bounds3 bounds = ComputeBounds(proxy_model);
  // The hand pinches the top of the proxy (below its studs for a Duplo figure) across its depth.
  grip_height_ = bounds.max.z() - kDuploStudHeight;
  HandOptions hand = config.hand;
  const double depth = bounds.max.y() - bounds.min.y();
  if (depth >= 0.01 && depth <= 0.08) hand.grip_width = depth;
  if (config.render.hand) hand_ = scene_.AddMoving("hand", BuildHandAndForearm(hand));
  if (config.render.slider) slider_ = scene_.AddMoving("slider", BuildSliderBlock());
  SetFrame(Rigid3::Identity(), 0.0);  // a valid, committed scene from the start
}

void TableTopScene::SetFrame(const Rigid3& table_T_proxy, double slider_value) {
  scene_.SetPose(proxy_, table_T_proxy);
  if (config_.render.hand) {
    // The hand holds the proxy from behind (+y, the animator's side): when the proxy has turned
    // its back to the animator, the hand grips it the other way round (a half turn about z).
    const Eigen::Vector3d x_axis = table_T_proxy.rotation * Eigen::Vector3d::UnitX();
    const double yaw = std::atan2(x_axis.y(), x_axis.x());
    const double turn = std::abs(yaw) > std::numbers::pi / 2 ? std::numbers::pi : 0.0;
    const Rigid3 proxy_T_grip(Yaw(turn), Eigen::Vector3d(0, 0, grip_height_));
    scene_.SetPose(hand_, table_T_proxy * proxy_T_grip);
  }
  if (config_.render.slider) {
    scene_.SetPose(slider_, LikeBoxSliderPose(config_.scene, std::clamp(slider_value, -5.0, 5.0)));
  }
  scene_.Commit();
}

nlohmann::json RenderSummary::ToJson() const {
  nlohmann::json j;
  j["frames"] = frames;
  j["render_seconds"] = seconds;
  j["write_seconds"] = write_seconds;
  j["frames_per_second"] = seconds > 0 ? frames / seconds : 0.0;
  j["missing_fraction"] = missing_fraction;
  j["rays"] = timings.rays;
  j["pixels_recast"] = timings.pixels_recast;
  j["seconds_per_step"] = {{"cast", timings.cast},
                           {"shade", timings.shade},
                           {"occlusion", timings.occlusion},
                           {"noise", timings.noise}};
  return j;
}

RenderSummary RenderSequence(const RenderConfig& config, const std::filesystem::path& out,
                             const std::function<void(int, int)>& progress) {
  const RenderOptions& r = config.render;
  // Read and check every input before the first frame.
  const TriangleMesh proxy_model = LoadProxyModel(r.proxy, r.proxy_scale);
  std::optional<Trajectory> trajectory;
  if (!r.trajectory.empty()) {
    trajectory = ReadTum(r.trajectory);
    if (static_cast<int>(trajectory->size()) < r.frames) {
      ThrowBadValue("render.trajectory (" + r.trajectory + ")",
                    std::to_string(trajectory->size()) + " poses",
                    "at least render.frames = " + std::to_string(r.frames));
    }
  }
  std::optional<Annotation> annotation;
  if (!r.annotation.empty()) {
    annotation = ReadAnnotationCsv(r.annotation);
    if (static_cast<int>(annotation->values.size()) < r.frames) {
      ThrowBadValue("render.annotation (" + r.annotation + ")",
                    std::to_string(annotation->values.size()) + " values",
                    "at least render.frames = " + std::to_string(r.frames));
    }
  }
  TableTopScene table_top(config, proxy_model);
  KinectSensor sensor(config.sensor, &table_top.scene(), table_top.table_T_camera());
  const Rigid3 depth_T_table = sensor.world_T_depth_camera().Inverse();

  RgbdCameraInfo camera;
  camera.depth_intrinsics = sensor.depth_intrinsics();
  camera.color_intrinsics = sensor.color_intrinsics();
  camera.depth_scale = kTumDepthScale;
  camera.color_T_depth = sensor.color_T_depth();
  camera.sensor = {{"model", "mmh synthetic Kinect v1"},
                   {"registered", config.sensor.registered},
                   {"calibration", mmh::ToJson(config.sensor.calibration)},
                   {"seed", config.sensor.seed}};
  RgbdFolderWriter writer(out, camera);
  std::unique_ptr<FakenectWriter> fakenect;
  if (r.fakenect) fakenect = std::make_unique<FakenectWriter>(out.string() + ".fakenect");

  RenderSummary summary;
  RgbdFrame frame;
  Trajectory groundtruth;
  Annotation slider_truth;
  BopFrames bop;
  double missing_sum = 0.0;
  for (int i = 0; i < r.frames; ++i) {
    const double t = i / config.sensor.frame_rate;
    const Rigid3 table_T_proxy = trajectory ? trajectory->poses[i] : config.motion.TableTProxy(t);
    const double slider = annotation ? annotation->values[i] : config.motion.SliderValue(t);
    const auto t0 = Clock::now();
    table_top.SetFrame(table_T_proxy, slider);
    sensor.Render(i, r.mode, &frame);
    const auto t1 = Clock::now();
    writer.Add(frame);
    if (fakenect) {
      fakenect->Add(frame.timestamp, RawDisparityFromDepth(frame, config.sensor.calibration),
                    frame.rgb);
    }
    summary.write_seconds += std::chrono::duration<double>(Clock::now() - t1).count();
    summary.seconds += std::chrono::duration<double>(t1 - t0).count();
    const Rigid3 camera_T_proxy = depth_T_table * table_T_proxy;
    groundtruth.timestamps.push_back(frame.timestamp);
    groundtruth.poses.push_back(camera_T_proxy);
    slider_truth.timestamps.push_back(frame.timestamp);
    slider_truth.values.push_back(std::clamp(slider, -5.0, 5.0));
    bop.push_back({BopObjectPose{1, camera_T_proxy}});
    missing_sum += static_cast<double>(std::count(frame.depth.begin(), frame.depth.end(), 0)) /
                   frame.depth.size();
    if (progress) progress(i + 1, r.frames);
  }
  summary.frames = r.frames;
  summary.missing_fraction = missing_sum / r.frames;
  summary.timings = sensor.timings();

  // The setup's calibration, for the tracker: where the camera stands and where the Like box is.
  nlohmann::json scene_json;
  const Rigid3 camera_T_table = depth_T_table;
  scene_json["camera_T_table"] = {{"translation",
                                   {camera_T_table.translation.x(), camera_T_table.translation.y(),
                                    camera_T_table.translation.z()}},
                                  {"quaternion_xyzw",
                                   {camera_T_table.rotation.x(), camera_T_table.rotation.y(),
                                    camera_T_table.rotation.z(), camera_T_table.rotation.w()}}};
  scene_json["table"] = mmh::ToJson(config.scene);
  scene_json["slider_block_size"] = kSliderBlockSize;
  scene_json["groundtruth"] = "groundtruth.txt: camera_T_proxy of the depth camera";
  writer.Finish(groundtruth, {{"scene", scene_json}});
  WritePly(proxy_model, out / "model.ply");
  WriteAnnotationCsv(out / "slider.csv", slider_truth);
  WriteFileAtomically(out / "scene.json", scene_json.dump(2) + "\n");
  if (fakenect) fakenect->Finish();
  if (r.bop) {
    EnsureDirectory(out / "bop" / "models");
    WriteBopScene(out / "bop", bop, camera.depth_intrinsics, camera.depth_scale);
    WritePly(proxy_model, out / "bop" / "models" / "obj_000001.ply", 1000.0);
  }
  return summary;
}

}  // namespace mmh::sim
