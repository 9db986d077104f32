// The synthetic Kinect v1 (DESIGN.md, "Kinect v1 model"): renders a RayScene into 640x480 depth
// and colour frames with the sensor's disparity quantisation, axial and lateral noise, IR shadow,
// missing data at discontinuities and grazing angles, range limits, and colour with shading and
// sensor noise.
//
// Per frame, in this order (docs/sensor.md has the derivations):
//  1. geometry: camera rays against the scene, keeping per pixel only depth, disparity, incidence
//     cosine and shaded colour. Incremental mode casts the static scene once and afterwards only
//     the pixels that each moving object's projected cluster boxes cover, against that object
//     alone (nearer hits replace the cached static ones); full mode re-casts the static scene at
//     every pixel, then the same moving-object casts. Both give the same frame.
//  2. occlusion of the projector (IR shadow) and, for registered depth, of the IR camera: both
//     sit on the camera's x axis, so a point is hidden from them exactly when a nearer point of the
//     same image row covers it in their view: a row scan with a running extremum.
//  3. per pixel, with noise from a counter-based generator keyed by (seed, frame, pixel), so that
//     a frame is the same for any thread count and SIMD level: lateral noise (edge pixels take
//     their neighbour's depth), axial noise sigma_z(z, theta) (Box-Muller normals), the disparity
//     lattice, missing pixels (shadow, edges, grazing angles, range, speckle), and colour noise
//     (each noisy byte drawn exactly from its rounded, clamped normal by the alias method).
// Sequences render fastest with RenderFrames (below): one scene and sensor per core.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "core/camera.h"
#include "core/rgbd_frame.h"
#include "core/rigid3.h"
#include "sim/kinect_model.h"
#include "sim/ray_scene.h"
#include "sim/structured_light.h"

namespace mmh::sim {

struct ColorModel {
  // Direction towards the light in the world (table) frame; normalised on use.
  double light_x = 0.3;
  double light_y = -0.4;
  double light_z = 1.0;
  // Lambertian shading in linear light: albedo * (ambient + diffuse * max(0, n.l)).
  double ambient = 0.35;
  double diffuse = 0.75;
  // Colour of pixels that see nothing (sRGB).
  int background_gray = 40;
  // Sensor noise per channel [8-bit units]: sigma^2 = read_noise^2 + shot_gain * value.
  double read_noise = 1.5;
  double shot_gain = 0.03;

  template <class V>
  void VisitFields(V& v) {
    v("light_x", light_x);
    v("light_y", light_y);
    v("light_z", light_z);
    v("ambient", ambient);
    v("diffuse", diffuse);
    v("background_gray", background_gray);
    v("read_noise", read_noise);
    v("shot_gain", shot_gain);
  }
  void Validate(const std::string& prefix) const;
};

struct MissingDataModel {
  // A pixel is at a depth discontinuity when the disparity of a 4-neighbour differs by more than
  // this [px of IR disparity, f b / z]; such pixels are missing with edge_probability (the Kinect's
  // correlation window straddles two surfaces there).
  double edge_jump_px = 0.6;
  double edge_probability = 0.5;
  // Missing probability rises linearly from 0 at grazing_from_deg to 1 at grazing_to_deg
  // (incidence angle between viewing ray and surface normal; the speckle is lost at grazing
  // angles).
  double grazing_from_deg = 70.0;
  double grazing_to_deg = 85.0;
  // Isolated dropouts anywhere [probability per pixel].
  double speckle_probability = 0.002;
  // The IR shadow: pixels the projector cannot see are missing.
  bool projector_shadow = true;
  // Registered depth: pixels the IR camera cannot see (it sits beside the colour camera) are
  // missing too.
  bool ir_camera_occlusion = true;

  template <class V>
  void VisitFields(V& v) {
    v("edge_jump_px", edge_jump_px);
    v("edge_probability", edge_probability);
    v("grazing_from_deg", grazing_from_deg);
    v("grazing_to_deg", grazing_to_deg);
    v("speckle_probability", speckle_probability);
    v("projector_shadow", projector_shadow);
    v("ir_camera_occlusion", ir_camera_occlusion);
  }
  void Validate(const std::string& prefix) const;
};

struct KinectSensorOptions {
  // Structured light (default: the speckle image and block matching, structured_light below) or
  // statistical (the fast per-pixel model; the axial, lateral and missing models apply only to it,
  // except missing.projector_shadow and missing.ir_camera_occlusion, which apply to both).
  SensorMode mode = SensorMode::kStructuredLight;
  // Intrinsics of the delivered images: with registered depth both depth and colour are in the
  // colour camera's image (ROS defaults 525 / 319.5 / 239.5).
  PinholeIntrinsics intrinsics;
  // Registered depth (true, as the Kinect drivers deliver it) or the IR camera's own image
  // (false: depth with ir_intrinsics from the IR camera, colour with `intrinsics`).
  bool registered = true;
  PinholeIntrinsics ir_intrinsics{640, 480, 580.0, 580.0, 319.5, 239.5};
  // The IR camera sits this far along -x of the colour camera [m] (Kinect v1: about 2.5 cm); the
  // projector sits calibration.baseline along +x of the IR camera.
  double ir_camera_offset = 0.025;
  KinectCalibration calibration;
  // Range limits [m]: depths outside are missing.
  double min_depth = 0.5;
  double max_depth = 4.0;
  // Noise on (false: the exact depth on the lattice, no random missing data; for geometry tests).
  bool noise = true;
  // Disparity quantisation on (false: continuous depth, rounded only to the depth unit).
  bool quantise = true;
  AxialNoiseModel axial;
  LateralNoiseModel lateral;
  MissingDataModel missing;
  ColorModel color;
  StructuredLightOptions structured_light;
  double frame_rate = 30.0;  // [Hz]
  uint64_t seed = 1;

  template <class V>
  void VisitFields(V& v) {
    v("mode", mode);
    v("intrinsics", intrinsics);
    v("registered", registered);
    v("ir_intrinsics", ir_intrinsics);
    v("ir_camera_offset", ir_camera_offset);
    v("calibration", calibration);
    v("min_depth", min_depth);
    v("max_depth", max_depth);
    v("noise", noise);
    v("quantise", quantise);
    v("axial", axial);
    v("lateral", lateral);
    v("missing", missing);
    v("color", color);
    v("structured_light", structured_light);
    v("frame_rate", frame_rate);
    v("seed", seed);
  }
  void Validate(const std::string& prefix) const;
};

enum class RenderMode { kIncremental, kFull };

// Time per step [s], summed over frames, and counts.
struct SensorTimings {
  double cast = 0.0;  // ray casting, with the write-back that shades the newly cast pixels
  // Surface colour of newly cast pixels: now part of the cast's write-back (counted in `cast`),
  // always 0; kept for readers of earlier summaries.
  double shade = 0.0;
  double restore = 0.0;    // copying the cached static scene back where the last frame changed it
  double occlusion = 0.0;  // projector / IR camera row scans
  double noise = 0.0;      // per-pixel noise, lattice, missing data, output
  uint64_t frames = 0;
  uint64_t rays = 0;
  uint64_t pixels_recast = 0;

  SensorTimings& operator+=(const SensorTimings& other);
};

class KinectSensor {
 public:
  // The scene must outlive the sensor; world_T_camera is the colour camera's pose in the world
  // (table) frame. Options are validated (InputError naming `options_name`.field).
  KinectSensor(const KinectSensorOptions& options, const RayScene* scene,
               const Rigid3& world_T_camera, const std::string& options_name = "sensor");
  ~KinectSensor();
  KinectSensor(const KinectSensor&) = delete;
  KinectSensor& operator=(const KinectSensor&) = delete;

  // Renders frame `index` of the scene in its current (committed) state into `frame`, reusing its
  // buffers. Timestamp index / frame_rate.
  void Render(int index, RenderMode mode, RgbdFrame* frame);
  RgbdFrame Render(int index, RenderMode mode = RenderMode::kIncremental);

  // Pose of the depth camera in the world frame (the colour camera when registered).
  Rigid3 world_T_depth_camera() const;
  // The geometry every rendered frame carries (RgbdFrame's fields of the same names).
  const PinholeIntrinsics& depth_intrinsics() const;
  const PinholeIntrinsics& color_intrinsics() const;
  Rigid3 color_T_depth() const;
  const Rigid3& world_T_camera() const;
  const KinectSensorOptions& options() const;
  const SensorTimings& timings() const;
  void ResetTimings();

  // Structured-light mode: when kept (off by default), per depth pixel of the last rendered
  // frame why it is missing (MissingCause::kValid where it is not); empty otherwise.
  void KeepMissingCauses(bool keep);
  std::span<const MissingCause> missing_causes() const;

  // The per-pixel noise runs in hand-written AVX-512 kernels where the CPU has them, else in AVX2
  // ones where it has those, otherwise in portable ones; all give the same bytes. For tests and
  // benchmarks: false selects the portable kernels for every sensor of the process; returns
  // whether vector kernels are now in use.
  static bool SetVectorKernels(bool enabled);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Frame-level parallelism: several scenes, each with its own sensor, render whole frames at once
// (a frame is too little work to keep two cores busy from inside). A frame is a pure function of
// the scene state, the seed and its index, so the frames are exactly those of one sensor rendering
// them in order, for any number of workers and either mode (tested).
struct SensorWorker {
  // Puts this worker's own scene into the state of frame `index` and commits it (for example
  // TableTopScene::SetFrame with that frame's proxy pose and slider value).
  std::function<void(int index)> pose_scene;
  // Renders that scene; the sensor's options must be the same for every worker.
  KinectSensor* sensor = nullptr;
};

// Renders frames [first, first + count) on up to workers.size() threads (oneTBB; each worker
// renders one frame at a time) and hands them to consume in frame order, one call at a time, on
// any thread. Exceptions from pose_scene, Render or consume stop the run and propagate.
void RenderFrames(std::span<const SensorWorker> workers, int first, int count, RenderMode mode,
                  const std::function<void(const RgbdFrame&)>& consume);

// The workers' timings, summed.
SensorTimings TotalTimings(std::span<const SensorWorker> workers);

}  // namespace mmh::sim
