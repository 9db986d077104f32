// One simulated recording: the table-top scene with its proxy, hand and slider block, a motion for
// the proxy and a slider track, rendered by the Kinect model into a TUM RGB-D folder (and,
// optionally, a fakenect dump and BOP ground truth). `mmh render` is a thin layer over this.
//
// The motion comes from a story performed by a simulated participant (the config's "scenario",
// people/scenario.h: a recording session renders the take, an annotation session renders the
// participant annotating it with the slider block while it plays), or from a TUM trajectory file
// (table_T_proxy) and an annotation CSV, or from a built-in demo walk and slider sweep.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/config.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"
#include "people/scenario.h"
#include "sim/kinect_sensor.h"
#include "sim/props.h"

namespace mmh::sim {

std::span<const std::pair<RenderMode, const char*>> EnumNames(RenderMode);

// What a story-driven recording shows (paper, "Recording a Take" and "Annotating the Takes").
enum class RenderSession {
  kRecording,   // the hand moves the proxy through the take; the slider block rests
  kAnnotation,  // the take plays on screen; the hand moves the slider block; the proxy rests
};
std::span<const std::pair<RenderSession, const char*>> EnumNames(RenderSession);

// The Kinect's placement in the table frame: at `position`, looking at `look_at`, its image x axis
// horizontal (parallel to the table). By default 0.85 m from the play area's centre: structured
// light loses the Duplo proxy's studs and edges at the 1.17 m of (0, -0.9, 0.75) (docs/sensor.md).
struct CameraPlacement {
  double x = 0.0, y = -0.65, z = 0.55;                       // [m]
  double look_at_x = 0.0, look_at_y = 0.0, look_at_z = 0.0;  // [m]
  // The camera turned about its viewing axis [deg], from the look-at pose whose image x axis is
  // horizontal, towards its image y (down): a real camera's roll (the real views of
  // tests/data/real/ycbv/views).
  double roll_deg = 0.0;

  template <class V>
  void VisitFields(V& v) {
    v("x", x);
    v("y", y);
    v("z", z);
    v("look_at_x", look_at_x);
    v("look_at_y", look_at_y);
    v("look_at_z", look_at_z);
    v("roll_deg", roll_deg);
  }
  void Validate(const std::string& prefix) const;
  // table_T_camera (camera frame: x right, y down, z forward).
  Rigid3 TableTCamera() const;
};

// The built-in demo walk: the proxy goes round an ellipse in the play area with a stepping bounce
// and yaw swings, the slider sweeps between dislike and like.
struct DemoMotionOptions {
  double radius_x = 0.12;        // [m]
  double radius_y = 0.07;        // [m]
  double round_period = 8.0;     // [s] per round
  double step_rate = 2.0;        // [steps / s]
  double bounce_height = 0.012;  // [m]
  double yaw_swing = 0.25;       // [rad] amplitude of the head-turn-like yaw swing
  double slider_period = 5.0;    // [s] per sweep

  template <class V>
  void VisitFields(V& v) {
    v("radius_x", radius_x);
    v("radius_y", radius_y);
    v("round_period", round_period);
    v("step_rate", step_rate);
    v("bounce_height", bounce_height);
    v("yaw_swing", yaw_swing);
    v("slider_period", slider_period);
  }
  void Validate(const std::string& prefix) const;
  Rigid3 TableTProxy(double t) const;
  double SliderValue(double t) const;
};

struct RenderOptions {
  // Frames to render; 0: the whole take (story), the whole trajectory file, or 150 (demo walk).
  int frames = 0;
  RenderMode mode = RenderMode::kIncremental;
  // The proxy: a Duplo assembly (.json, see configs/proxies/) or a mesh (.obj, .ply) scaled by
  // proxy_scale (e.g. 0.001 for millimetres). Empty: the Soldier figure.
  std::string proxy;
  double proxy_scale = 1.0;
  // table_T_proxy per frame (TUM); empty: the demo walk. Its rows are used in order, one per frame.
  std::string trajectory;
  // Slider values per frame (annotation CSV); empty: the demo sweep.
  std::string annotation;
  bool hand = true;
  bool slider = true;
  // With a story (scenario.story): take `take` of the scenario's object (0-based; the skill index:
  // the takes a participant performed before it count), recorded or annotated.
  int take = 0;
  RenderSession session = RenderSession::kRecording;
  // zlib level of the PNGs: 1 writes about 3.5 times faster than zlib's default 6, for files
  // 5-15 % larger with the same pixels.
  int png_compression = 1;
  // Outputs besides the TUM RGB-D folder.
  bool fakenect = false;
  bool bop = false;

  template <class V>
  void VisitFields(V& v) {
    v("frames", frames);
    v("mode", mode);
    v("proxy", proxy);
    v("proxy_scale", proxy_scale);
    v("trajectory", trajectory);
    v("annotation", annotation);
    v("hand", hand);
    v("slider", slider);
    v("take", take);
    v("session", session);
    v("png_compression", png_compression);
    v("fakenect", fakenect);
    v("bop", bop);
  }
  void Validate(const std::string& prefix) const;
};

// Every section of a render config: how a recording is rendered. What is performed and by whom
// (the scenario and the people's sections) is people::PeopleConfig.
struct RenderConfig {
  RenderOptions render;
  CameraPlacement camera;
  TableSceneOptions scene;
  HandOptions hand;
  KinectSensorOptions sensor;
  DemoMotionOptions motion;

  // Reads the render sections; the other sections of a run or study config (scenario and the
  // people, study, montage, track, metrics, viewer, scorers) may be present and are left to the
  // commands that use them.
  static RenderConfig FromConfig(const Config& config);
  nlohmann::json ToJson() const;
};

// The proxy's model in its own frame, from RenderOptions::proxy.
TriangleMesh LoadProxyModel(const std::string& proxy, double scale);

// The meshes of config `scene.objects`, in their order (file I/O: load them once for all the
// scenes of a recording). A missing or bad file is an InputError naming scene.objects[i].mesh.
std::vector<TriangleMesh> LoadSceneObjects(const TableSceneOptions& scene);

// The scene of one recording: static table top, the user's objects, proxy, hand, slider block.
class TableTopScene {
 public:
  // `object_meshes`: LoadSceneObjects(config.scene).
  TableTopScene(const RenderConfig& config, const TriangleMesh& proxy_model,
                const std::vector<TriangleMesh>& object_meshes);
  // Loads the objects' meshes itself (a single scene).
  TableTopScene(const RenderConfig& config, const TriangleMesh& proxy_model);
  enum class Hand { kOnProxy, kOnSlider };
  // Places the proxy, the slider block and the hand holding one of them; commits the scene.
  void SetFrame(const Rigid3& table_T_proxy, double slider_value, Hand hand = Hand::kOnProxy);
  const RayScene& scene() const { return scene_; }
  const Rigid3& table_T_camera() const { return table_T_camera_; }

 private:
  RenderConfig config_;
  RayScene scene_;
  Rigid3 table_T_camera_;
  uint32_t proxy_ = 0, hand_ = 0, slider_ = 0;
  double grip_height_ = 0.0;  // proxy frame z of the grasp point
};

// A story-driven recording's take.
struct RenderedTake {
  int frames = 0;             // the whole take's (the recording may render fewer)
  double mean_quality = 0.0;  // of the latent quality (people/take_quality.h)
  double skill = 0.0;         // the participant's skill at this take
  int flaws = 0;
  // Annotation sessions: the share of frames where the slider block sat at an end of its range.
  std::optional<double> clipped_fraction;
};

struct RenderSummary {
  int frames = 0;
  double seconds = 0.0;           // wall clock of rendering and writing (they overlap)
  double write_seconds = 0.0;     // encoding and writing, summed over threads
  double missing_fraction = 0.0;  // mean over frames
  SensorTimings timings;
  std::optional<RenderedTake> take;  // story-driven recordings only
  nlohmann::json ToJson() const;
};

// A story-driven recording's sessions are scripted by sim/session_script.h (shared with `mmh run`,
// so that it renders exactly the frames `mmh render` renders for the same participant, take and
// session).

// Renders the sequence and writes `out` (a TUM RGB-D folder: rgb/, depth/, rgb.txt, depth.txt,
// groundtruth.txt = camera_T_proxy of the depth camera, camera.json), plus model.ply (the proxy's
// model for the tracker, metres), slider.csv (the true slider values), scene.json (camera_T_table,
// play area and Like box: the setup's calibration), fakenect/ and bop/ when enabled. A story adds
// take.tum (table_T_proxy of the whole take), take.csv (per frame: beat, performed action, latent
// quality and its factors; annotation sessions also the judgement, delay and slider), flaws.csv and
// participant.json. Everything is read and checked before the first frame; folders appear
// complete or not at all: `before_commit(staging, summary)`, when given, adds the caller's files
// (run.json, ...) to the staging folder before it is moved to `out`.
// `people` gives the scenario (people.scenario.story empty: the trajectory file or demo walk of
// config.render).
RenderSummary RenderSequence(const RenderConfig& config, const people::PeopleConfig& people,
                             const std::filesystem::path& out,
                             const std::function<void(int, int)>& progress = {},
                             const std::function<void(const std::filesystem::path&,
                                                      const RenderSummary&)>& before_commit = {});

}  // namespace mmh::sim
