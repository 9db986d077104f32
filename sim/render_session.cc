#include "sim/render_session.h"

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/mesh_io.h"
#include "core/rgbd_folder.h"
#include "core/tum_io.h"
#include "sim/bop_writer.h"
#include "sim/duplo.h"
#include "sim/fakenect_writer.h"
#include "sim/session_script.h"
#include "people/random.h"
#include "people/story.h"

namespace mmh::sim {
namespace {

using Clock = std::chrono::steady_clock;

Eigen::Quaterniond Yaw(double angle) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()));
}

// The BOP scene's images, depth/NNNNNN.png and rgb/NNNNNN.png by image id (BOP's layout, read by
// bop_toolkit and by `mmh track` / `mmh eval`), are the TUM folder's own files: hard links, so no
// second copy; copied where the file system refuses links. The depth scale of scene_camera.json is
// the TUM folder's, and the colour images are registered to the depth camera (one cam_K).
void LinkBopImages(const std::filesystem::path& staging,
                   const std::vector<std::pair<std::filesystem::path, std::filesystem::path>>& images,
                   const std::filesystem::path& scene) {
  EnsureDirectory(scene / "depth");
  EnsureDirectory(scene / "rgb");
  for (size_t id = 0; id < images.size(); ++id) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06zu.png", id);
    for (const auto& [source, folder] :
         {std::pair{images[id].first, "depth"}, std::pair{images[id].second, "rgb"}}) {
      const std::filesystem::path target = scene / folder / name;
      std::error_code error;
      std::filesystem::create_hard_link(staging / source, target, error);
      if (error) std::filesystem::copy_file(staging / source, target);
    }
  }
}

}  // namespace

TableTopScene::TableTopScene(const RenderConfig& config, const TriangleMesh& proxy_model)
    : TableTopScene(config, proxy_model, LoadSceneObjects(config.scene)) {}

TableTopScene::TableTopScene(const RenderConfig& config, const TriangleMesh& proxy_model,
                             const std::vector<TriangleMesh>& object_meshes)
    : config_(config), table_T_camera_(config.camera.TableTCamera()) {
  if (object_meshes.size() != config.scene.objects.size()) {
    throw std::logic_error("TableTopScene: " + std::to_string(object_meshes.size()) +
                           " object meshes for " + std::to_string(config.scene.objects.size()) +
                           " scene.objects");
  }
  for (const NamedMesh& part : BuildTableScene(config.scene)) {
    const uint32_t object = scene_.AddStatic(part.name, part.mesh, Rigid3::Identity());
    scene_.SetMaterial(object, config.scene.materials.ForObject(part.name));
  }
  for (size_t i = 0; i < config.scene.objects.size(); ++i) {
    const SceneObject& o = config.scene.objects[i];
    const uint32_t object = scene_.AddStatic(o.name, object_meshes[i], o.TableTObject());
    scene_.SetMaterial(object, o.material);
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
  for (int o = 0; o < scene_.object_count(); ++o) {
    if (scene_.is_moving(o)) scene_.SetMaterial(o, config.scene.materials.ForObject(scene_.object_name(o)));
  }
  SetFrame(Rigid3::Identity(), 0.0);  // a valid, committed scene from the start
}

void TableTopScene::SetFrame(const Rigid3& table_T_proxy, double slider_value, Hand hand) {
  scene_.SetPose(proxy_, table_T_proxy);
  const Rigid3 table_T_slider =
      LikeBoxSliderPose(config_.scene, std::clamp(slider_value, -5.0, 5.0));
  if (config_.render.hand && hand == Hand::kOnSlider) {
    // Pinching the block across its sides (fingers left, thumb right), the forearm reaching in
    // from the right, so that the camera sees the block's front face as it slides.
    scene_.SetPose(hand_, table_T_slider * Rigid3(Yaw(-std::numbers::pi / 2),
                                                  Eigen::Vector3d(0, 0, kDuploBrickHeight)));
  } else if (config_.render.hand) {
    // The hand holds the proxy from behind (+y, the animator's side): when the proxy has turned
    // its back to the animator, the hand grips it the other way round (a half turn about z).
    const Eigen::Vector3d x_axis = table_T_proxy.rotation * Eigen::Vector3d::UnitX();
    const double yaw = std::atan2(x_axis.y(), x_axis.x());
    const double turn = std::abs(yaw) > std::numbers::pi / 2 ? std::numbers::pi : 0.0;
    const Rigid3 proxy_T_grip(Yaw(turn), Eigen::Vector3d(0, 0, grip_height_));
    scene_.SetPose(hand_, table_T_proxy * proxy_T_grip);
  }
  if (config_.render.slider) {
    scene_.SetPose(slider_, table_T_slider);
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
  if (take) {
    j["take"] = {{"frames", take->frames},
                 {"mean_quality", take->mean_quality},
                 {"skill", take->skill},
                 {"flaws", take->flaws}};
    if (take->clipped_fraction) j["take"]["clipped_fraction"] = *take->clipped_fraction;
  }
  j["rays"] = timings.rays;
  j["pixels_recast"] = timings.pixels_recast;
  j["seconds_per_step"] = {{"cast", timings.cast},
                           {"restore", timings.restore},
                           {"occlusion", timings.occlusion},
                           {"noise", timings.noise}};
  return j;
}

namespace {

// The motion of a recording: per frame, the proxy's pose, the slider value and the hand.
struct Motion {
  int frames = 0;
  std::string proxy;  // proxy model file ("" = the Soldier)
  std::vector<Rigid3> table_T_proxy;
  std::vector<double> slider;
  TableTopScene::Hand hand = TableTopScene::Hand::kOnProxy;
  // Story-driven recordings.
  std::optional<StoryScript> script;
  std::optional<people::PerformedTake> take;
  std::optional<people::AnnotationSession> annotation;
};

Motion ResolveMotion(const RenderConfig& config, const people::PeopleConfig& people) {
  const RenderOptions& r = config.render;
  Motion motion;
  motion.proxy = r.proxy;
  if (!people.scenario.story.empty()) {
    if (!r.trajectory.empty()) {
      ThrowBadValue("render.trajectory", "\"" + r.trajectory + "\"",
                    "empty when scenario.story is given (the story's take is the motion)");
    }
    const StoryScript& script = motion.script.emplace(people, config.scene);
    motion.take = script.Perform(r.take);
    if (r.proxy.empty()) motion.proxy = script.ProxyFile();
    const int take_frames = motion.take->frames();
    motion.frames = r.frames == 0 ? take_frames : std::min(r.frames, take_frames);
    SessionFrames frames;
    if (r.session == RenderSession::kRecording) {
      frames = script.RecordingFrames(*motion.take, motion.frames);
    } else {
      motion.annotation = script.Annotate(*motion.take);
      frames = script.AnnotationFrames(*motion.annotation, motion.frames);
    }
    motion.table_T_proxy = std::move(frames.table_T_proxy);
    motion.slider = std::move(frames.slider);
    motion.hand = frames.hand;
    return motion;
  }
  std::optional<Trajectory> trajectory;
  if (!r.trajectory.empty()) trajectory = ReadTum(r.trajectory);
  motion.frames = r.frames != 0 ? r.frames
                  : trajectory  ? static_cast<int>(trajectory->size())
                                : 150;
  if (trajectory && static_cast<int>(trajectory->size()) < motion.frames) {
    ThrowBadValue("render.trajectory (" + r.trajectory + ")",
                  std::to_string(trajectory->size()) + " poses",
                  "at least render.frames = " + std::to_string(motion.frames));
  }
  std::optional<Annotation> annotation;
  if (!r.annotation.empty()) {
    annotation = ReadAnnotationCsv(r.annotation);
    if (static_cast<int>(annotation->values.size()) < motion.frames) {
      ThrowBadValue("render.annotation (" + r.annotation + ")",
                    std::to_string(annotation->values.size()) + " values",
                    "at least render.frames = " + std::to_string(motion.frames));
    }
  }
  for (int i = 0; i < motion.frames; ++i) {
    const double t = i / config.sensor.frame_rate;
    motion.table_T_proxy.push_back(trajectory ? trajectory->poses[i]
                                              : config.motion.TableTProxy(t));
    motion.slider.push_back(annotation ? annotation->values[i] : config.motion.SliderValue(t));
  }
  return motion;
}

// take.csv, flaws.csv, take.tum and participant.json of a story-driven recording.
void WriteStoryFiles(const Motion& motion, const people::PeopleConfig& people,
                     const std::filesystem::path& out) {
  const people::PerformedTake& take = *motion.take;
  const people::StoryObject& object = motion.script->story().objects[take.object];
  const double fps = people.performance.frame_rate;
  std::string csv =
      "frame,timestamp,beat,script_kind,performed_kind,progress,quality,fidelity,path,steadiness,"
      "expression,motion";
  if (motion.annotation) csv += ",judgement,delay,slider";
  csv += "\n";
  for (int i = 0; i < take.frames(); ++i) {
    const people::QualityTrace& q = take.quality;
    csv += std::to_string(i) + "," + FormatNumber(i / fps) + "," +
           std::to_string(take.script_beat[i]) + "," +
           people::BeatKindName(object.beats[take.script_beat[i]].kind) + "," +
           people::BeatKindName(take.performed_kind[i]) + "," + FormatNumber(take.script_progress[i]) +
           "," + FormatNumber(q.quality[i]) + "," + FormatNumber(q.fidelity[i]) + "," +
           FormatNumber(q.path[i]) + "," + FormatNumber(q.steadiness[i]) + "," +
           FormatNumber(q.expression[i]) + "," + FormatNumber(q.motion[i]);
    if (motion.annotation) {
      csv += "," + FormatNumber(motion.annotation->judgement[i]) + "," +
             FormatNumber(motion.annotation->delay[i]) + "," +
             FormatNumber(motion.annotation->slider[i]);
    }
    csv += "\n";
  }
  WriteFileAtomically(out / "take.csv", csv);
  std::string flaws = "kind,beat,first_frame,last_frame\n";
  for (const people::Flaw& f : take.flaws) {
    flaws += std::string(EnumName(f.kind)) + "," + std::to_string(f.beat) + "," +
             std::to_string(f.first_frame) + "," + std::to_string(f.last_frame) + "\n";
  }
  WriteFileAtomically(out / "flaws.csv", flaws);
  WriteTum(out / "take.tum", take.table_T_proxy);
  nlohmann::json participant;
  participant["index"] = motion.script->participant().index;
  participant["animator"] = mmh::ToJson(motion.script->participant().animator);
  participant["annotator"] = mmh::ToJson(motion.script->participant().annotator);
  participant["take"] = take.take;
  participant["skill_at_take"] = take.skill;
  WriteFileAtomically(out / "participant.json", participant.dump(2) + "\n");
}

// The scene and sensor of each rendering thread, and the workers that pose the scene for a frame.
struct SceneWorkers {
  SceneWorkers(const RenderConfig& config, const TriangleMesh& proxy_model, const Motion& motion,
               int count) {
    const std::vector<TriangleMesh> object_meshes = LoadSceneObjects(config.scene);
    for (int w = 0; w < count; ++w) {
      scenes.push_back(std::make_unique<TableTopScene>(config, proxy_model, object_meshes));
      sensors.push_back(std::make_unique<KinectSensor>(config.sensor, &scenes.back()->scene(),
                                                       scenes.back()->table_T_camera()));
      TableTopScene* scene = scenes.back().get();
      workers.push_back({[scene, &motion](int i) {
                           scene->SetFrame(motion.table_T_proxy[i], motion.slider[i], motion.hand);
                         },
                         sensors.back().get()});
    }
  }
  std::vector<std::unique_ptr<TableTopScene>> scenes;
  std::vector<std::unique_ptr<KinectSensor>> sensors;
  std::vector<SensorWorker> workers;
};

// camera.json of the rendered folder: the sensor's intrinsics, registration and calibration.
RgbdCameraInfo CameraInfo(const KinectSensor& sensor, const RenderConfig& config) {
  RgbdCameraInfo camera;
  camera.depth_intrinsics = sensor.depth_intrinsics();
  camera.color_intrinsics = sensor.color_intrinsics();
  camera.depth_scale = kTumDepthScale;
  camera.color_T_depth = sensor.color_T_depth();
  camera.sensor = {{"model", "mmh synthetic Kinect v1"},
                   {"registered", config.sensor.registered},
                   {"calibration", mmh::ToJson(config.sensor.calibration)},
                   {"seed", config.sensor.seed}};
  camera.png_compression = config.render.png_compression;
  return camera;
}

// scene.json: the setup's calibration, for the tracker: where the camera stands and where the Like
// box is.
nlohmann::json SetupJson(const Rigid3& camera_T_table, const RenderConfig& config) {
  nlohmann::json scene_json;
  scene_json["camera_T_table"] = {{"translation",
                                   {camera_T_table.translation.x(), camera_T_table.translation.y(),
                                    camera_T_table.translation.z()}},
                                  {"quaternion_xyzw",
                                   {camera_T_table.rotation.x(), camera_T_table.rotation.y(),
                                    camera_T_table.rotation.z(), camera_T_table.rotation.w()}}};
  scene_json["table"] = mmh::ToJson(config.scene);
  scene_json["slider_block_size"] = config.scene.slider_block_size;
  scene_json["groundtruth"] = "groundtruth.txt: camera_T_proxy of the depth camera";
  return scene_json;
}

}  // namespace

RenderSummary RenderSequence(
    const RenderConfig& config, const people::PeopleConfig& people, const std::filesystem::path& out,
    const std::function<void(int, int)>& progress,
    const std::function<void(const std::filesystem::path&, const RenderSummary&)>& before_commit) {
  const RenderOptions& r = config.render;
  // Read and check every input before the first frame.
  const Motion motion = ResolveMotion(config, people);
  const TriangleMesh proxy_model = LoadProxyModel(motion.proxy, r.proxy_scale);
  // One scene and sensor per thread: frames render in parallel (RenderFrames) and come back in
  // order; their PNGs are encoded in parallel too. The bytes do not depend on the thread count.
  const int threads = std::max(1, tbb::this_task_arena::max_concurrency());
  const SceneWorkers scene_workers(config, proxy_model, motion, std::min(threads, motion.frames));
  const std::vector<SensorWorker>& workers = scene_workers.workers;
  const KinectSensor& sensor = *scene_workers.sensors.front();
  const Rigid3 depth_T_table = sensor.world_T_depth_camera().Inverse();
  const RgbdCameraInfo camera = CameraInfo(sensor, config);
  RgbdFolderWriter writer(out, camera);
  std::unique_ptr<FakenectWriter> fakenect;
  if (r.fakenect) fakenect = std::make_unique<FakenectWriter>(out.string() + ".fakenect");

  RenderSummary summary;
  Trajectory groundtruth;
  Annotation slider_truth;
  BopFrames bop;
  double missing_sum = 0.0;
  std::atomic<std::int64_t> write_nanoseconds{0};
  tbb::task_group writes;
  int pending = 0;
  const auto start = Clock::now();
  RenderFrames(workers, 0, motion.frames, r.mode, [&](const RgbdFrame& frame) {
    const int i = frame.index;
    if (fakenect) {
      fakenect->Add(frame.timestamp, RawDisparityFromDepth(frame, config.sensor.calibration),
                    frame.rgb);
    }
    const Rigid3 camera_T_proxy = depth_T_table * motion.table_T_proxy[i];
    groundtruth.timestamps.push_back(frame.timestamp);
    groundtruth.poses.push_back(camera_T_proxy);
    slider_truth.timestamps.push_back(frame.timestamp);
    slider_truth.values.push_back(std::clamp(motion.slider[i], -5.0, 5.0));
    bop.push_back({BopObjectPose{1, camera_T_proxy}});
    missing_sum += static_cast<double>(std::count(frame.depth.begin(), frame.depth.end(), 0)) /
                   frame.depth.size();
    // Encoding a frame's PNGs takes longer than rendering it: hand it to another thread, with a
    // bounded number of frames in flight.
    if (pending == 2 * threads) {
      writes.wait();
      pending = 0;
    }
    ++pending;
    writes.run([&writer, &write_nanoseconds, copy = frame] {
      const auto t0 = Clock::now();
      writer.Add(copy);
      write_nanoseconds +=
          std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
    });
    if (progress) progress(i + 1, motion.frames);
  });
  writes.wait();
  summary.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  summary.write_seconds = 1e-9 * static_cast<double>(write_nanoseconds.load());
  summary.frames = motion.frames;
  summary.missing_fraction = missing_sum / motion.frames;
  if (motion.take) {
    RenderedTake& take = summary.take.emplace();
    take.frames = motion.take->frames();
    take.mean_quality = motion.take->MeanQuality();
    take.skill = motion.take->skill;
    take.flaws = static_cast<int>(motion.take->flaws.size());
    if (motion.annotation) take.clipped_fraction = motion.annotation->clipped_fraction;
  }
  summary.timings = TotalTimings(workers);

  const nlohmann::json scene_json = SetupJson(depth_T_table, config);
  // Everything goes into the staging folder before it is moved into place: a kill at any moment
  // leaves no partial folder under `out` (a later render removes the staging folder).
  const std::filesystem::path& staging = writer.staging();
  WritePly(proxy_model, staging / "model.ply");
  WriteAnnotationCsv(staging / "slider.csv", slider_truth);
  WriteFileAtomically(staging / "scene.json", scene_json.dump(2) + "\n");
  if (motion.take) WriteStoryFiles(motion, people, staging);
  if (r.bop) {
    EnsureDirectory(staging / "bop" / "models");
    WriteBopScene(staging / "bop", bop, camera.depth_intrinsics, camera.depth_scale);
    WritePly(proxy_model, staging / "bop" / "models" / "obj_000001.ply", 1000.0);
    LinkBopImages(staging, writer.AddedImages(), staging / "bop");
  }
  if (before_commit) before_commit(staging, summary);
  writer.Finish(groundtruth, {{"scene", scene_json}});
  if (fakenect) fakenect->Finish();
  return summary;
}

}  // namespace mmh::sim
