#include "sim/sensor_check_run.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <tuple>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/tum_io.h"
#include "sim/anchor_noise.h"
#include "sim/kinect_sensor.h"
#include "sim/silhouette_bleed.h"

namespace mmh::sim {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The missing runs beside depth steps of one sensor's frames, pooled for FitStepLaw.
struct StepRuns {
  std::vector<StepRun> shadow, edge;
  int frames = 0;

  void Add(const std::vector<float>& depth_m, int width, int height, double fx_px) {
    CollectStepRuns(depth_m, width, height, fx_px, &shadow, &edge);
    ++frames;
  }
  StepLawRow Fit(std::string name, double fx_px, double shadow_geometry_m = kNaN,
                 double edge_geometry_m = kNaN) const {
    StepLawOptions all;
    all.min_step_px_per_m *= fx_px / kStepLawFocalPx;
    StepLawOptions small = all;
    small.max_step_px_per_m = kSmallStepPxPerM * fx_px / kStepLawFocalPx;
    return {std::move(name),
            fx_px,
            frames,
            shadow_geometry_m,
            edge_geometry_m,
            FitStepLaw(shadow, all),
            FitStepLaw(edge, all),
            FitStepLaw(shadow, small),
            FitStepLaw(edge, small)};
  }
  // A rendered sensor's: its geometry beside the fits.
  StepLawRow Fit(std::string name, double fx_px, const KinectSensorOptions& sensor) const {
    const double baseline = sensor.calibration.baseline;
    return sensor.registered ? Fit(std::move(name), fx_px, baseline - sensor.ir_camera_offset,
                                   sensor.ir_camera_offset)
                             : Fit(std::move(name), fx_px, baseline, 0.0);
  }
};

// The first frame's residual correlation with the frames kTemporalLags later; with the camera's
// motions (camera_k_T_camera_0 for every frame k, or none), also following the surface.
SensorCheckReport::TemporalRow TemporalStructure(const std::string& name,
                                                 const DepthSequence& sequence,
                                                 const std::vector<Rigid3>& motions = {}) {
  SensorCheckReport::TemporalRow row{name, {}, {}};
  for (const int lag : kTemporalLags) {
    if (lag >= static_cast<int>(sequence.depth_m.size())) {
      ThrowBadValue(sequence.name + ": frames", std::to_string(sequence.depth_m.size()),
                    "at least " + std::to_string(lag + 1) + " frames (the temporal structure)");
    }
    const std::vector<float>& first = sequence.depth_m[0];
    row.lags.push_back(AnalyseTemporalCorrelation(first, sequence.depth_m[lag], sequence.width,
                                                  sequence.height, sequence.intrinsics));
    if (motions.empty()) continue;
    row.surface_lags.push_back(AnalyseTemporalCorrelation(
        first,
        SurfaceAlignedDepth(first, sequence.depth_m[lag], sequence.width, sequence.height,
                            sequence.intrinsics, motions.at(lag)),
        sequence.width, sequence.height, sequence.intrinsics));
  }
  return row;
}

// The first `frames` frames of the demo walk in one sensor mode: every frame's statistics into
// report.rendered_frames, the first frame's error structure (and, for structured light, its
// missing pixels by cause) into the report. Returns the first frame's statistics.
SensorStatistics RenderInMode(TableTopScene& table_top, const RenderConfig& config, SensorMode mode,
                            int frames, const SensorCheckOptions& options,
                            SensorCheckReport& report) {
  KinectSensorOptions sensor_options = config.sensor;
  sensor_options.mode = mode;
  const bool structured = mode == SensorMode::kStructuredLight;
  const std::string name = structured ? "rendered SL" : "rendered stat.";
  KinectSensor sensor(sensor_options, &table_top.scene(), table_top.table_T_camera());
  sensor.KeepMissingCauses(structured);
  const std::size_t first = report.rendered_frames.size();
  const int last_lag = std::end(kTemporalLags)[-1];
  std::vector<std::vector<float>> sequence;  // frames 0 .. last_lag, for the temporal structure
  PinholeIntrinsics intrinsics;
  StepRuns step_runs;
  for (int i = 0; i < std::max(frames, last_lag + 1); ++i) {
    const double t = i / config.sensor.frame_rate;
    table_top.SetFrame(config.motion.TableTProxy(t), config.motion.SliderValue(t));
    const RgbdFrame frame = sensor.Render(i);
    const int width = frame.depth_intrinsics.width;
    const int height = frame.depth_intrinsics.height;
    intrinsics = frame.depth_intrinsics;
    SensorCheckOptions frame_options = options;
    frame_options.intrinsics = frame.depth_intrinsics;
    frame_options.calibration = config.sensor.calibration;
    frame_options.noise = config.sensor.axial;
    const std::vector<float> depth_m = DepthMetresFromUnits(frame.depth, frame.depth_scale);
    if (i <= last_lag) sequence.push_back(depth_m);
    if (i >= frames) continue;
    report.rendered_frames.push_back(
        ComputeSensorStatistics(name, depth_m, width, height, frame_options));
    step_runs.Add(depth_m, width, height, frame.depth_intrinsics.fx);
    if (i > 0) continue;
    report.rendered_depth_m[structured ? 1 : 0] = depth_m;
    report.structure_names.push_back(name);
    report.structures.push_back(AnalyseErrorStructure(depth_m, width, height,
                                                      frame.depth_intrinsics,
                                                      config.sensor.calibration,
                                                      config.sensor.axial));
    if (structured) {
      report.cause_table = FormatCauseTable(ClassifyMissing(depth_m, width, height),
                                            sensor.missing_causes());
    }
  }
  report.temporal.push_back(TemporalStructure(
      name, {name, intrinsics.width, intrinsics.height, intrinsics, std::move(sequence)}));
  report.step_laws.push_back(step_runs.Fit(name, intrinsics.fx, sensor_options));
  return report.rendered_frames[first];
}

// The like-for-like view over time in structured light (SensorCheckReport::view_temporal): frames
// 0 .. the last lag from a still camera (only the IR noise changes), and with the real camera's
// motion. The trajectory's object poses are the real camera_T_object carried into the table frame
// through the first frame's table fit, so a still object seen by camera_k = table_T_object_0
// table_T_object_k^-1 table_T_camera has the real frame k's camera_T_object: the pattern slides
// over the scene as in the real recording. `first_m`: frame 0, rendered already (the scene posed
// at poses[0]). First, when the real view has the frames, its own row; the real and the moved rows
// also following the surface, by the camera motions camera_k_T_camera_0 = table_T_camera_k^-1
// table_T_camera.
std::vector<SensorCheckReport::TemporalRow> ViewOverTime(const RealView& real,
                                                         const TableTopScene& scene,
                                                         KinectSensorOptions options,
                                                         const std::vector<Rigid3>& poses,
                                                         std::vector<float> first_m,
                                                         const PinholeIntrinsics& intrinsics) {
  const int lags = std::end(kTemporalLags)[-1] + 1;
  if (static_cast<int>(poses.size()) < lags) {
    ThrowBadValue(real.name + ": render.trajectory", std::to_string(poses.size()) + " poses",
                  "at least " + std::to_string(lags) + " (the temporal lags)");
  }
  options.mode = SensorMode::kStructuredLight;
  DepthSequence still{"view, SL, still", intrinsics.width, intrinsics.height, intrinsics, {first_m}};
  DepthSequence moving{"view, SL, the real camera's motion", intrinsics.width, intrinsics.height,
                       intrinsics, {std::move(first_m)}};
  KinectSensor still_sensor(options, &scene.scene(), scene.table_T_camera());
  std::vector<Rigid3> motions{Rigid3()};  // camera_k_T_camera_0
  for (int k = 1; k < lags; ++k) {
    const RgbdFrame frame = still_sensor.Render(k);
    still.depth_m.push_back(DepthMetresFromUnits(frame.depth, frame.depth_scale));
    const Rigid3 table_T_camera_k = poses.front() * poses[k].Inverse() * scene.table_T_camera();
    motions.push_back(table_T_camera_k.Inverse() * scene.table_T_camera());
    KinectSensor moved(options, &scene.scene(), table_T_camera_k);
    const RgbdFrame moved_frame = moved.Render(k);
    moving.depth_m.push_back(DepthMetresFromUnits(moved_frame.depth, moved_frame.depth_scale));
  }
  std::vector<SensorCheckReport::TemporalRow> rows;
  // The real view's own frames, the same motions (when it has enough).
  if (real.later_frames.size() + 1 >= static_cast<size_t>(lags)) {
    DepthSequence frames{real.name, real.width, real.height, real.intrinsics, {real.depth_m}};
    for (int k = 1; k < lags; ++k) frames.depth_m.push_back(real.later_frames[k - 1].depth_m);
    rows.push_back(TemporalStructure(real.name, frames, motions));
  }
  rows.push_back(TemporalStructure(still.name, still));
  rows.push_back(TemporalStructure(moving.name, moving, motions));
  return rows;
}

// A desk's front edge in a depth image of the bare geometry (width x height, metres, no pixel
// missing but beyond the range; the depth camera at table_T_camera): the pixels of the table top
// (at most 5 cm below it, in the table frame) with a 4-neighbour on the floor beyond the desk
// (more than 5 cm below the top). None in a view whose table reaches past the picture.
std::vector<uint8_t> DeskEdgeMask(const std::vector<float>& depth_m,
                                  const PinholeIntrinsics& intrinsics,
                                  const Rigid3& table_T_camera) {
  const int width = intrinsics.width, height = intrinsics.height;
  constexpr double kBelowTop = -0.05;            // [m]
  std::vector<int8_t> level(depth_m.size(), 0);  // 1: the top (or above it), -1: below, 0: none
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t p = static_cast<size_t>(v) * width + u;
      const double z = depth_m[p];
      if (!(z > 0)) continue;
      const Eigen::Vector3d camera_p((u - intrinsics.cx) / intrinsics.fx * z,
                                     (v - intrinsics.cy) / intrinsics.fy * z, z);
      level[p] = (table_T_camera * camera_p).z() < kBelowTop ? -1 : 1;
    }
  }
  std::vector<uint8_t> edge(depth_m.size(), 0);
  for (int v = 1; v + 1 < height; ++v) {
    for (int u = 1; u + 1 < width; ++u) {
      const size_t p = static_cast<size_t>(v) * width + u;
      edge[p] = level[p] == 1 && (level[p - 1] == -1 || level[p + 1] == -1 ||
                                  level[p - width] == -1 || level[p + width] == -1);
    }
  }
  return edge;
}

// A mask (non-zero = in) on another pixel grid over the same rays: ResampleDepthNearest.
std::vector<uint8_t> ResampleMask(const std::vector<uint8_t>& mask, const PinholeIntrinsics& from,
                                  const PinholeIntrinsics& to) {
  const std::vector<float> mapped =
      ResampleDepthNearest(std::vector<float>(mask.begin(), mask.end()), from, to);
  std::vector<uint8_t> out(mapped.size());
  for (size_t p = 0; p < mapped.size(); ++p) out[p] = mapped[p] > 0.5f;
  return out;
}

// The object's neighbourhood (AnalyseNeighbourhood) with its silhouette's bleed and erosion
// (MeasureSilhouetteBleed), in a frame whose pixels are `pixel_scale` of the rendered sensor's: the
// bleed's pixel counts are the rendered sensor's, carried to the frame's pixels.
NeighbourhoodStructure AroundObject(const std::vector<float>& depth_m, int width, int height,
                                    std::span<const uint8_t> mask, int radius_px,
                                    double pixel_scale, std::span<const uint8_t> excluded = {}) {
  NeighbourhoodStructure n =
      AnalyseNeighbourhood(depth_m, width, height, mask, radius_px, {}, excluded);
  SilhouetteBleedOptions options;
  auto in_frame = [&](int px) { return static_cast<int>(std::lround(px / pixel_scale)); };
  options.reference_px = in_frame(options.reference_px);
  options.min_run_px = in_frame(options.min_run_px);
  options.max_px = in_frame(options.max_px);
  options.background_from_px = in_frame(options.background_from_px);
  options.background_to_px = in_frame(options.background_to_px);
  const SilhouetteBleed bleed =
      MeasureSilhouetteBleed(depth_m, width, height, mask, options, excluded);
  n.shadow_side_bleed_px = bleed.shadow_side.bleed_px;
  n.edge_side_bleed_px = bleed.edge_side.bleed_px;
  n.shadow_side_erosion_px = bleed.shadow_side.erosion_px;
  n.edge_side_erosion_px = bleed.edge_side.erosion_px;
  n.shadow_side_ends = bleed.shadow_side.ends;
  n.edge_side_ends = bleed.edge_side.ends;
  MissingInside(depth_m, width, height, mask, in_frame(kInteriorErosionPx), excluded, n);
  return n;
}

// The exact depth on the lattice without the IR shadow, the IR camera's occlusion and the
// missing-pixel rules: the bare geometry, as a graphics engine renders it.
KinectSensorOptions WithoutTheSensorsHoles(KinectSensorOptions options) {
  options.mode = SensorMode::kStatistical;
  options.noise = false;
  options.missing.edge_probability = 0;
  options.missing.speckle_probability = 0;
  options.missing.grazing_from_deg = 89;
  options.missing.grazing_to_deg = 90;
  options.missing.projector_shadow = false;
  options.missing.ir_camera_occlusion = false;
  return options;
}

// The real view rendered in both modes, and each frame's neighbourhood of the object beside the
// real frame's (docs/sensor.md, "Like for like").
void CompareLikeForLike(const RealView& view, SensorCheckReport& report) {
  const RenderConfig& config = view.config;
  if (config.render.trajectory.empty()) {
    ThrowBadValue(view.name + ": render.trajectory", "\"\"",
                  "the object's poses, the first the real frame's");
  }
  // ReadTum refuses a file without poses.
  const std::vector<Rigid3> poses = ReadTum(config.render.trajectory).poses;
  const Rigid3& table_T_object = poses.front();
  TableTopScene scene(config, LoadProxyModel(config.render.proxy, config.render.proxy_scale));
  // The object's mask: where the exact depth with the object is valid and nearer than without it
  // (the object moved far below the floor).
  KinectSensorOptions exact = config.sensor;
  exact.mode = SensorMode::kStatistical;
  exact.noise = false;
  auto exact_depth = [&](const Rigid3& pose) {
    scene.SetFrame(pose, 0.0);
    KinectSensor sensor(exact, &scene.scene(), scene.table_T_camera());
    const RgbdFrame frame = sensor.Render(0);
    return std::make_pair(DepthMetresFromUnits(frame.depth, frame.depth_scale),
                          frame.depth_intrinsics);
  };
  const auto [without, intrinsics] =
      exact_depth(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -100)));
  const auto with = exact_depth(table_T_object).first;
  std::vector<uint8_t> mask(with.size(), 0);
  for (size_t p = 0; p < with.size(); ++p) {
    mask[p] = with[p] > 0 && (!(without[p] > 0) || with[p] < without[p] - 0.005f);
  }
  if (std::find(mask.begin(), mask.end(), uint8_t{1}) == mask.end()) {
    ThrowBadValue(view.name + ": the object in the rendered view", "not seen",
                  "the object in the camera's view (render.trajectory's first pose, camera)");
  }
  const double focal = intrinsics.fx;
  const int width = intrinsics.width, height = intrinsics.height;
  if (!(view.intrinsics.fx > 0) || view.mask.size() != view.depth_m.size() ||
      view.depth_m.size() != static_cast<size_t>(view.width) * view.height) {
    ThrowBadValue(view.name + ": real frame", std::to_string(view.width) + "x" +
                                                  std::to_string(view.height) + ", " +
                                                  std::to_string(view.mask.size()) + " mask pixels",
                  "a depth image, its intrinsics and a mask of the same size");
  }
  const double real_scale = focal / view.intrinsics.fx;
  const int real_radius = static_cast<int>(std::lround(kNeighbourhoodRadiusPx / real_scale));
  report.like_for_like.push_back(
      {view.name, real_scale,
       AroundObject(view.depth_m, view.width, view.height, view.mask, real_radius, real_scale)});
  report.real_near.push_back(report.like_for_like.back().structure);
  StepRuns real_runs;
  real_runs.Add(view.depth_m, view.width, view.height, view.intrinsics.fx);
  for (const RealView::Frame& frame : view.later_frames) {
    if (frame.depth_m.size() != view.depth_m.size() || frame.mask.size() != view.mask.size() ||
        frame.others.size() != view.others.size()) {
      ThrowBadValue(view.name + ": later frame", std::to_string(frame.depth_m.size()) + " pixels",
                    "the first frame's size, with its mask and other objects' mask");
    }
    report.real_near.push_back(
        AroundObject(frame.depth_m, view.width, view.height, frame.mask, real_radius, real_scale));
    real_runs.Add(frame.depth_m, view.width, view.height, view.intrinsics.fx);
  }
  report.view_step_laws.push_back(
      real_runs.Fit(view.name.substr(0, view.name.rfind(" frame ")), view.intrinsics.fx));
  // Near the other objects (grown as the neighbourhood is), on the real grid and on the rendered
  // one (the same rays).
  std::vector<uint8_t> real_away, rendered_away;
  if (!view.others.empty()) {
    if (view.others.size() != view.mask.size()) {
      ThrowBadValue(view.name + ": other objects' mask", std::to_string(view.others.size()),
                    std::to_string(view.mask.size()) + " pixels (the frame's)");
    }
    real_away = GrowMask(view.others, view.width, view.height, real_radius);
    rendered_away = ResampleMask(real_away, view.intrinsics, intrinsics);
    report.like_for_like_away.push_back(
        {view.name, real_scale,
         AroundObject(view.depth_m, view.width, view.height, view.mask, real_radius, real_scale,
                      real_away)});
    report.real_away.push_back(report.like_for_like_away.back().structure);
    for (const RealView::Frame& frame : view.later_frames) {
      report.real_away.push_back(
          AroundObject(frame.depth_m, view.width, view.height, frame.mask, real_radius, real_scale,
                       GrowMask(frame.others, view.width, view.height, real_radius)));
    }
  }
  // Along the desk's edge: its pixels in the bare geometry (the exact render without the object,
  // the IR shadow, the IR camera's occlusion and the missing-pixel rules, so that the top's and the
  // floor's pixels meet), grown as the object's mask is, the object's and the other objects'
  // neighbourhoods left out; mapped to the real grid as the other objects' mask is mapped to the
  // rendered one.
  const KinectSensorOptions bare = WithoutTheSensorsHoles(config.sensor);
  scene.SetFrame(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -100)), 0.0);
  KinectSensor bare_sensor(bare, &scene.scene(), scene.table_T_camera());
  const RgbdFrame bare_frame = bare_sensor.Render(0);
  const std::vector<uint8_t> rendered_desk =
      DeskEdgeMask(DepthMetresFromUnits(bare_frame.depth, bare_frame.depth_scale), intrinsics,
                   bare_sensor.world_T_depth_camera());
  const bool desk =
      std::find(rendered_desk.begin(), rendered_desk.end(), uint8_t{1}) != rendered_desk.end();
  std::vector<uint8_t> rendered_desk_out = GrowMask(mask, width, height, kNeighbourhoodRadiusPx);
  if (!rendered_away.empty()) {
    for (size_t p = 0; p < rendered_desk_out.size(); ++p) {
      rendered_desk_out[p] = rendered_desk_out[p] || rendered_away[p];
    }
  }
  if (desk) {
    const std::vector<uint8_t> real_desk = ResampleMask(rendered_desk, intrinsics, view.intrinsics);
    const std::vector<uint8_t> real_out =
        ResampleMask(rendered_desk_out, intrinsics, view.intrinsics);
    report.like_for_like_desk.push_back(
        {view.name, real_scale,
         AnalyseNeighbourhood(view.depth_m, view.width, view.height, real_desk, real_radius, {},
                              real_out)});
    report.real_desk.push_back(report.like_for_like_desk.back().structure);
    for (const RealView::Frame& frame : view.later_frames) {
      report.real_desk.push_back(AnalyseNeighbourhood(frame.depth_m, view.width, view.height,
                                                      real_desk, real_radius, {}, real_out));
    }
  }
  auto analyse_desk = [&](const std::vector<float>& depth_m) {
    return AnalyseNeighbourhood(depth_m, width, height, rendered_desk, kNeighbourhoodRadiusPx, {},
                                rendered_desk_out);
  };
  report.view_depth_m[0] = view.depth_m;
  report.view_width = view.width;
  report.view_height = view.height;
  // The rendered sensor's pixel grid over the real camera's field of view (the same rays through
  // the pixel centres, focal length `focal`), and that grid with every pixel shown as 2 x 2.
  PinholeIntrinsics native = intrinsics;
  native.width = static_cast<int>(std::lround(view.width * real_scale));
  native.height = static_cast<int>(std::lround(view.height * real_scale));
  native.cx = (view.intrinsics.cx + 0.5) * real_scale - 0.5;
  native.cy = (view.intrinsics.cy + 0.5) * real_scale - 0.5;
  PinholeIntrinsics shown = native;
  shown.width = 2 * native.width;
  shown.height = 2 * native.height;
  shown.fx = 2 * native.fx;
  shown.fy = 2 * native.fy;
  shown.cx = 2 * (native.cx + 0.5) - 0.5;
  shown.cy = 2 * (native.cy + 0.5) - 0.5;
  report.native_view_width = shown.width;
  report.native_view_height = shown.height;
  auto on_native_grid = [&](const std::vector<float>& depth_m, const PinholeIntrinsics& from) {
    return ResampleDepthNearest(ResampleDepthNearest(depth_m, from, native), native, shown);
  };
  report.native_view_depth_m[0] = on_native_grid(view.depth_m, view.intrinsics);
  // The small planar patches on the native grid (SensorCheckReport::view_patches): the real frames
  // first.
  auto native_patches = [&](const std::vector<float>& depth_m, const PinholeIntrinsics& from) {
    return AnalyseErrorStructure(ResampleDepthNearest(depth_m, from, native), native.width,
                                 native.height, native, config.sensor.calibration,
                                 config.sensor.axial);
  };
  SensorCheckReport::PatchRow real_patches{view.name, {}};
  real_patches.draws.push_back(native_patches(view.depth_m, view.intrinsics));
  for (const RealView::Frame& frame : view.later_frames) {
    real_patches.draws.push_back(native_patches(frame.depth_m, view.intrinsics));
  }
  const std::string structured_over_patterns =
      "view, SL, " + std::to_string(view.patterns) + " pattern" + (view.patterns > 1 ? "s" : "");
  report.view_patches = {
      std::move(real_patches), {"view, stat.", {}}, {structured_over_patterns, {}}};
  scene.SetFrame(table_T_object, 0.0);
  std::vector<float> structured_depth_m;  // the structured-light frame, for the view over time
  StepRuns pattern_runs;                  // structured light over the patterns
  for (const SensorMode mode : {SensorMode::kStatistical, SensorMode::kStructuredLight}) {
    KinectSensorOptions options = config.sensor;
    options.mode = mode;
    KinectSensor sensor(options, &scene.scene(), scene.table_T_camera());
    const RgbdFrame frame = sensor.Render(0);
    const bool structured = mode == SensorMode::kStructuredLight;
    std::vector<float> depth_m = DepthMetresFromUnits(frame.depth, frame.depth_scale);
    report.like_for_like.push_back(
        {structured ? "view, SL" : "view, stat.", 1.0,
         AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0)});
    if (!rendered_away.empty()) {
      report.like_for_like_away.push_back(
          {structured ? "view, SL" : "view, stat.", 1.0,
           AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0, rendered_away)});
    }
    if (desk) {
      report.like_for_like_desk.push_back(
          {structured ? "view, SL" : "view, stat.", 1.0, analyse_desk(depth_m)});
    }
    // The picture shows the rendered frame at the real one's scale and field of view.
    report.view_depth_m[structured ? 2 : 1] =
        ResampleDepthNearest(depth_m, intrinsics, view.intrinsics);
    report.native_view_depth_m[structured ? 2 : 1] = on_native_grid(depth_m, intrinsics);
    report.view_patches[structured ? 2 : 1].draws.push_back(native_patches(depth_m, intrinsics));
    if (structured) {
      pattern_runs.Add(depth_m, width, height, focal);
      structured_depth_m = std::move(depth_m);
    } else {
      StepRuns runs;
      runs.Add(depth_m, width, height, focal);
      report.view_step_laws.push_back(runs.Fit("view, stat.", focal, options));
    }
  }
  report.view_temporal =
      ViewOverTime(view, scene, config.sensor, poses, std::move(structured_depth_m), intrinsics);
  // Structured light over speckle patterns: the first is the row above.
  report.pattern_near.push_back(report.like_for_like.back().structure);
  if (!rendered_away.empty())
    report.pattern_away.push_back(report.like_for_like_away.back().structure);
  if (desk) report.pattern_desk.push_back(report.like_for_like_desk.back().structure);
  report.pattern_seeds.push_back(config.sensor.structured_light.pattern_seed);
  for (int k = 1; k < view.patterns; ++k) {
    KinectSensorOptions options = config.sensor;
    options.mode = SensorMode::kStructuredLight;
    options.structured_light.pattern_seed += k;
    KinectSensor sensor(options, &scene.scene(), scene.table_T_camera());
    const RgbdFrame frame = sensor.Render(0);
    const std::vector<float> depth_m = DepthMetresFromUnits(frame.depth, frame.depth_scale);
    report.pattern_seeds.push_back(options.structured_light.pattern_seed);
    report.pattern_near.push_back(
        AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0));
    if (!rendered_away.empty()) {
      report.pattern_away.push_back(
          AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0, rendered_away));
    }
    if (desk) report.pattern_desk.push_back(analyse_desk(depth_m));
    pattern_runs.Add(depth_m, width, height, focal);
    report.view_patches[2].draws.push_back(native_patches(depth_m, intrinsics));
  }
  report.view_step_laws.push_back(
      pattern_runs.Fit(structured_over_patterns, focal, config.sensor));
  // Matched on the other grid than the config's (StructuredLightOptions::match_on_ir_grid): the
  // IR camera's, registered to the colour camera's, or the delivered one (the shortcut).
  report.other_grid_is_ir = !config.sensor.structured_light.match_on_ir_grid;
  for (int k = 0; k < view.patterns; ++k) {
    KinectSensorOptions options = config.sensor;
    options.mode = SensorMode::kStructuredLight;
    options.registered = true;
    options.structured_light.match_on_ir_grid = report.other_grid_is_ir;
    options.structured_light.pattern_seed += k;
    KinectSensor sensor(options, &scene.scene(), scene.table_T_camera());
    const RgbdFrame frame = sensor.Render(0);
    report.pattern_near_other_grid.push_back(
        AroundObject(DepthMetresFromUnits(frame.depth, frame.depth_scale), width, height, mask,
                     kNeighbourhoodRadiusPx, 1.0));
  }
  // The anchors (sim/anchor_noise.h) on the view's render without the sensor's holes (a graphics
  // engine's depth, what they post-process: no IR shadow, no IR-camera occlusion), one noise seed
  // per pattern of structured light; and from a still camera over the temporal lags.
  scene.SetFrame(table_T_object, 0.0);
  KinectSensor clean_sensor(bare, &scene.scene(), scene.table_T_camera());
  const RgbdFrame clean_frame = clean_sensor.Render(0);
  const std::vector<float> clean = DepthMetresFromUnits(clean_frame.depth, clean_frame.depth_scale);
  for (const AnchorModel model : {AnchorModel::kIclNuim, AnchorModel::kSimKinect}) {
    SensorCheckReport::AnchorRows rows{AnchorName(model), {}, {}, {}};
    SensorCheckReport::PatchRow patches{"view, " + AnchorName(model), {}};
    for (int k = 0; k < view.patterns; ++k) {
      const std::vector<float> depth_m =
          ApplyAnchorNoise(model, clean, width, height, config.sensor.seed + k, 0);
      patches.draws.push_back(native_patches(depth_m, intrinsics));
      rows.near.push_back(AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0));
      if (!rendered_away.empty()) {
        rows.away.push_back(
            AroundObject(depth_m, width, height, mask, kNeighbourhoodRadiusPx, 1.0, rendered_away));
      }
      if (desk) rows.desk.push_back(analyse_desk(depth_m));
    }
    DepthSequence still{"view, " + rows.name + ", still", width, height, intrinsics, {}};
    for (int k = 0; k <= std::end(kTemporalLags)[-1]; ++k) {
      still.depth_m.push_back(ApplyAnchorNoise(model, clean, width, height, config.sensor.seed, k));
    }
    report.view_temporal.push_back(TemporalStructure(still.name, still));
    report.anchors.push_back(std::move(rows));
    report.view_patches.push_back(std::move(patches));
  }
}

}  // namespace

SensorCheckReport RunSensorCheck(const std::filesystem::path& real_frames,
                                 const RenderConfig& config, int frames,
                                 const DepthSequence* real_sequence, const RealView* real_view,
                                 const DepthSequence* kinect_sequence) {
  SensorCheckReport report;
  if (real_view != nullptr) CompareLikeForLike(*real_view, report);
  if (real_sequence != nullptr) {
    report.temporal.push_back(TemporalStructure(real_sequence->name, *real_sequence));
  }
  const SensorCheckOptions options;
  // Real frames: TUM (5000 units per metre), NYU raw disparity, SUN (millimetres).
  const DepthImage tum = ReadDepthPng16(real_frames / "TUM_depth.png");
  report.width = tum.width;
  report.height = tum.height;
  report.tum_depth_m = DepthMetresFromUnits(tum.values, 1.0 / 5000);
  report.columns.push_back(ComputeSensorStatistics("TUM real", report.tum_depth_m, tum.width,
                                                   tum.height, options));
  const DepthImage nyu = ReadNyuRawDisparity(real_frames / "NYU_depth.pgm");
  const std::vector<float> nyu_m = DepthMetresFromNyuRaw(nyu.values);
  report.columns.push_back(ComputeSensorStatistics("NYU real", nyu_m, nyu.width, nyu.height,
                                                   options, &nyu.values));
  const DepthImage sun = ReadSunDepth(real_frames / "SUN_depth.png");
  report.columns.push_back(ComputeSensorStatistics(
      "SUN real", DepthMetresFromUnits(sun.values, 0.001), sun.width, sun.height, options));
  // The error structure of the Kinect v1 frames (SUN's sensor differs) beside the rendered ones.
  report.structure_names = {"TUM real", "NYU real"};
  report.structures = {
      AnalyseErrorStructure(report.tum_depth_m, tum.width, tum.height, options.intrinsics,
                            options.calibration, options.noise),
      AnalyseErrorStructure(nyu_m, nyu.width, nyu.height, options.intrinsics,
                            options.calibration, options.noise)};
  // TUM's frames are registered to the colour camera at the ROS default intrinsics (TUM's own
  // calibration differs by 1-2 %); NYU's raw frame is the IR camera's.
  StepRuns tum_runs, nyu_runs;
  tum_runs.Add(report.tum_depth_m, tum.width, tum.height, options.intrinsics.fx);
  nyu_runs.Add(nyu_m, nyu.width, nyu.height, kNyuDepthIntrinsics.fx);
  report.step_laws = {tum_runs.Fit("TUM real", options.intrinsics.fx),
                      nyu_runs.Fit("NYU real (raw, IR camera)", kNyuDepthIntrinsics.fx)};
  if (kinect_sequence != nullptr) {
    StepRuns runs;
    for (const std::vector<float>& depth_m : kinect_sequence->depth_m) {
      runs.Add(depth_m, kinect_sequence->width, kinect_sequence->height,
               kinect_sequence->intrinsics.fx);
    }
    report.step_laws.push_back(runs.Fit(kinect_sequence->name, kinect_sequence->intrinsics.fx));
    // Its first frame's error structure beside TUM's and NYU's (at its own intrinsics).
    report.structure_names.push_back(kinect_sequence->name);
    report.structures.push_back(AnalyseErrorStructure(
        kinect_sequence->depth_m.front(), kinect_sequence->width, kinect_sequence->height,
        kinect_sequence->intrinsics, options.calibration, options.noise));
  }

  // Both sensor modes over the same scene.
  TableTopScene table_top(config, LoadProxyModel(config.render.proxy, config.render.proxy_scale));
  for (const SensorMode mode : {SensorMode::kStatistical, SensorMode::kStructuredLight}) {
    report.columns.push_back(RenderInMode(table_top, config, mode, frames, options, report));
  }
  // The anchors on the demo walk's first frame rendered without the sensor's holes.
  const KinectSensorOptions clean = WithoutTheSensorsHoles(config.sensor);
  table_top.SetFrame(config.motion.TableTProxy(0), config.motion.SliderValue(0));
  KinectSensor clean_sensor(clean, &table_top.scene(), table_top.table_T_camera());
  const RgbdFrame frame = clean_sensor.Render(0);
  const std::vector<float> clean_m = DepthMetresFromUnits(frame.depth, frame.depth_scale);
  for (const AnchorModel model : {AnchorModel::kIclNuim, AnchorModel::kSimKinect}) {
    report.structure_names.push_back("anchor " + AnchorName(model));
    report.structures.push_back(AnalyseErrorStructure(
        ApplyAnchorNoise(model, clean_m, frame.depth_intrinsics.width,
                         frame.depth_intrinsics.height, config.sensor.seed, 0),
        frame.depth_intrinsics.width, frame.depth_intrinsics.height, frame.depth_intrinsics,
        config.sensor.calibration, config.sensor.axial));
  }
  return report;
}

std::string SensorCheckReport::Format() const {
  std::string text = FormatSensorTable(columns) + "\n" +
                     FormatRealismTable(structure_names, structures, 0,
                                        {structures.size() - 4, structures.size() - 3,
                                         structures.size() - 2, structures.size() - 1}) +
                     "\n" + "structured light, first frame: " + cause_table;
  // The temporal structure: one row per sequence, rho and the windows at each lag.
  text += "\nresidual correlation with the first frame (planar windows kept in both)\n";
  char line[160];
  std::snprintf(line, sizeof(line), "%-40s", "sequence");
  text += line;
  for (const int lag : kTemporalLags) {
    std::snprintf(line, sizeof(line), "  lag %d: rho (windows)", lag);
    text += line;
  }
  text += "\n";
  auto add_rows = [&](const std::vector<TemporalRow>& rows) {
    for (const TemporalRow& row : rows) {
      std::snprintf(line, sizeof(line), "%-40s", row.name.c_str());
      text += line;
      for (const auto* lags : {&row.lags, &row.surface_lags}) {
        for (const TemporalCorrelation& t : *lags) {
          std::snprintf(line, sizeof(line), "  %14.3f (%5d)", t.rho, t.patches);
          text += line;
        }
      }
      text += "\n";
    }
  };
  add_rows(temporal);
  if (!like_for_like.empty()) text += FormatLikeForLike() + FormatAnchors() + FormatViewPatches();
  if (!view_temporal.empty()) {
    text +=
        "\nthe real view over time: residual correlation with the first frame (as above; then "
        "following the surface:\nframe k's depth where the point seen at each pixel of the "
        "first moved with the camera)\n";
    std::snprintf(line, sizeof(line), "%-40s", "sequence");
    text += line;
    for (const char* along : {"", "surface "}) {
      for (const int lag : kTemporalLags) {
        std::snprintf(line, sizeof(line), "  %slag %d: rho (windows)", along, lag);
        text += line;
      }
    }
    text += "\n";
    add_rows(view_temporal);
  }
  return text + FormatStepLaws();
}

std::string SensorCheckReport::FormatStepLaws() const {
  std::string text =
      "\nstep law of the missing runs beside depth steps (sim/step_law.h): run = B x + c, "
      "x = fx (1/z_near - 1/z_far) [px/m];\nB [cm] with its 95 % bootstrap interval, c in the "
      "frames' pixels; @100: the run beside a step of 100 px/m at 525 px (5 px of shadow at 5 "
      "cm), in pixels at 525 px; model: the rendered sensor's own distances\n";
  char line[256];
  std::snprintf(line, sizeof(line),
                "%-38s %7s %6s | %5s %9s %19s %6s %6s %6s | %5s %9s %19s %6s %6s %6s\n", "frames",
                "fx", "frames", "runs", "x 10-90%", "shadow: B [cm]", "c", "@100", "model", "runs",
                "x 10-90%", "edge: B [cm]", "c", "@100", "model");
  const std::string header = line;
  auto centimetres = [](double m) { return 100 * m; };
  auto add = [&](const StepLawRow& row, bool small) {
    std::snprintf(line, sizeof(line), "%-38s %7.1f %6d", row.name.c_str(), row.fx_px, row.frames);
    text += line;
    for (const auto& [law, model] :
         {std::pair{small ? &row.shadow_small : &row.shadow, row.shadow_geometry_m},
          std::pair{small ? &row.edge_small : &row.edge, row.edge_geometry_m}}) {
      // The fitted run beside a step of 100 px / m at 525 px, in pixels at 525 px.
      const double at_100 = law->slope_m * 100 + law->intercept_px * kStepLawFocalPx / row.fx_px;
      std::snprintf(line, sizeof(line), " | %5d %4.0f-%-4.0f %6.2f (%5.2f-%5.2f) %6.2f %6.2f",
                    law->runs, law->step_p10_px_per_m, law->step_p90_px_per_m,
                    centimetres(law->slope_m), centimetres(law->slope_low_m),
                    centimetres(law->slope_high_m), law->intercept_px, at_100);
      text += line;
      if (std::isfinite(model)) {
        std::snprintf(line, sizeof(line), " %6.2f", centimetres(model));
        text += line;
      } else {
        text += "      -";
      }
    }
    text += "\n";
  };
  for (const bool small : {false, true}) {
    if (small) {
      std::snprintf(line, sizeof(line),
                    "small steps only (x up to %.0f px/m at %.0f px: the objects on a table top)\n",
                    kSmallStepPxPerM, kStepLawFocalPx);
    } else {
      std::snprintf(line, sizeof(line), "all steps (x from 40 px/m at %.0f px)\n", kStepLawFocalPx);
    }
    text += line + header;
    for (const StepLawRow& row : step_laws) add(row, small);
    for (const StepLawRow& row : view_step_laws) add(row, small);
  }
  return text;
}

std::string SensorCheckReport::FormatLikeForLike() const {
  char title[200];
  std::string text;
  auto add = [&](const std::vector<NeighbourhoodRow>& rows,
                 const std::vector<NeighbourhoodStructure>& patterns,
                 const std::vector<NeighbourhoodStructure>& real_frames, const char* format) {
    if (rows.empty()) return;
    std::snprintf(title, sizeof(title), format, kNeighbourhoodRadiusPx);
    text += FormatNeighbourhoods(title, rows, patterns, real_frames);
  };
  if (!like_for_like.empty()) {
    std::snprintf(title, sizeof(title),
                  "\nlike for like: around the object (its mask grown by %d px), band widths in "
                  "the rendered sensor's pixels\n",
                  kNeighbourhoodRadiusPx);
    text += FormatNeighbourhoods(title, like_for_like, pattern_near, real_near,
                                 pattern_near_other_grid);
  }
  add(like_for_like_away, pattern_away, real_away,
      "\nlike for like, away from the other objects (the real frame's other labels grown by %d "
      "px, left out of both)\n");
  add(like_for_like_desk, pattern_desk, real_desk,
      "\nlike for like, along the desk's edge (the table top's pixels beside the floor's grown "
      "by %d px, the objects' left out)\n");
  return text;
}

namespace {

// The statistics of the like-for-like tables, in the rendered sensor's pixels.
struct NeighbourhoodStatistic {
  const char* label;
  const char* key;  // in sensor_check.json
  double (*value)(const NeighbourhoodStructure&, double pixel_scale);
};
constexpr NeighbourhoodStatistic kNeighbourhoodStatistics[] = {
    {"missing [%]", "missing_share",
     [](const NeighbourhoodStructure& n, double) { return 100 * n.missing_share; }},
    {"missing inside [%]", "interior_missing_share",
     [](const NeighbourhoodStructure& n, double) { return 100 * n.interior_missing_share; }},
    {"shadow band [px]", "shadow_band_px",
     [](const NeighbourhoodStructure& n, double s) { return n.shadow_band_px * s; }},
    {"edge band [px]", "edge_band_px",
     [](const NeighbourhoodStructure& n, double s) { return n.edge_band_px * s; }},
    {"shadow band across [px]", "shadow_band_across_px",
     [](const NeighbourhoodStructure& n, double s) { return n.shadow_band_across_px * s; }},
    {"edge band across [px]", "edge_band_across_px",
     [](const NeighbourhoodStructure& n, double s) { return n.edge_band_across_px * s; }},
    {"bleed, shadow side [px]", "shadow_side_bleed_px",
     [](const NeighbourhoodStructure& n, double s) { return n.shadow_side_bleed_px * s; }},
    {"bleed, edge side [px]", "edge_side_bleed_px",
     [](const NeighbourhoodStructure& n, double s) { return n.edge_side_bleed_px * s; }},
    {"eroded, shadow side [px]", "shadow_side_erosion_px",
     [](const NeighbourhoodStructure& n, double s) { return n.shadow_side_erosion_px * s; }},
    {"eroded, edge side [px]", "edge_side_erosion_px",
     [](const NeighbourhoodStructure& n, double s) { return n.edge_side_erosion_px * s; }},
};

// Mean, sample standard deviation, minimum and maximum of values over patterns or frames. A band's
// width is NaN where a frame has no run of that kind: such values are left out (all left out:
// NaN).
struct ValueSpread {
  double mean = 0, sd = 0, min = 0, max = 0;
};
ValueSpread SpreadOfValues(const std::vector<double>& all) {
  std::vector<double> values;
  for (const double value : all) {
    if (std::isfinite(value)) values.push_back(value);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (values.empty()) return {nan, nan, nan, nan};
  ValueSpread r{0, 0, *std::min_element(values.begin(), values.end()),
                *std::max_element(values.begin(), values.end())};
  for (const double value : values) r.mean += value / values.size();
  for (const double value : values) {
    r.sd += values.size() > 1 ? (value - r.mean) * (value - r.mean) / (values.size() - 1) : 0.0;
  }
  r.sd = std::sqrt(r.sd);
  return r;
}

// One statistic over patterns or frames, in the rendered sensor's pixels, each divided by
// `divisor` (the real frame's value for ratios, 1 for values).
ValueSpread SpreadOf(const NeighbourhoodStatistic& statistic,
                     const std::vector<NeighbourhoodStructure>& rows, double pixel_scale,
                     double divisor = 1.0) {
  std::vector<double> values;
  for (const NeighbourhoodStructure& n : rows) {
    values.push_back(statistic.value(n, pixel_scale) / divisor);
  }
  return SpreadOfValues(values);
}

// The mean of a statistic over rendered rows (in the rendered sensor's pixels) over its mean over
// real frames (whose pixels real_scale turns into the rendered sensor's).
double RatioOfMeans(const NeighbourhoodStatistic& statistic,
                    const std::vector<NeighbourhoodStructure>& rendered,
                    const std::vector<NeighbourhoodStructure>& real, double real_scale) {
  return SpreadOf(statistic, rendered, 1.0).mean / SpreadOf(statistic, real, real_scale).mean;
}

}  // namespace

std::string SensorCheckReport::FormatNeighbourhoods(
    const std::string& title, const std::vector<NeighbourhoodRow>& rows,
    const std::vector<NeighbourhoodStructure>& patterns,
    const std::vector<NeighbourhoodStructure>& real_frames,
    const std::vector<NeighbourhoodStructure>& other_grid_patterns) const {
  char line[200];
  std::string text = title;
  std::snprintf(line, sizeof(line), "%-24s", "");
  text += line;
  for (const NeighbourhoodRow& row : rows) {
    std::snprintf(line, sizeof(line), "%26s", row.name.c_str());
    text += line;
  }
  text += "     SL/real";
  if (patterns.size() > 1) {
    std::snprintf(line, sizeof(line), "  %2zu patterns: SL/real", patterns.size());
    text += line;
  }
  text += "   goal\n";
  const NeighbourhoodRow& real = rows.front();
  const NeighbourhoodRow& sl = rows.back();
  // A statistic no row has (the silhouette's, along the desk's edge) is not printed.
  auto measured = [&](const NeighbourhoodStatistic& statistic) {
    return std::any_of(rows.begin(), rows.end(), [&](const NeighbourhoodRow& row) {
      return !std::isnan(statistic.value(row.structure, row.pixel_scale));
    });
  };
  for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
    if (!measured(statistic)) continue;
    std::snprintf(line, sizeof(line), "%-24s", statistic.label);
    text += line;
    for (const NeighbourhoodRow& row : rows) {
      std::snprintf(line, sizeof(line), "%26.2f", statistic.value(row.structure, row.pixel_scale));
      text += line;
    }
    const double real_value = statistic.value(real.structure, real.pixel_scale);
    std::snprintf(line, sizeof(line), "%12.2f",
                  statistic.value(sl.structure, sl.pixel_scale) / real_value);
    text += line;
    if (patterns.size() > 1) {
      const ValueSpread r = SpreadOf(statistic, patterns, 1.0, real_value);
      std::snprintf(line, sizeof(line), "  %7.2f +- %.2f (%.2f-%.2f)", r.mean, r.sd, r.min, r.max);
      text += line;
    }
    text += "   0.8-1.2\n";
  }
  // A row of two counts per frame.
  auto counts = [&](const char* label, int NeighbourhoodStructure::*first,
                    int NeighbourhoodStructure::*second) {
    std::snprintf(line, sizeof(line), "%-24s", label);
    text += line;
    for (const NeighbourhoodRow& row : rows) {
      std::snprintf(
          line, sizeof(line), "%26s",
          (std::to_string(row.structure.*first) + ", " + std::to_string(row.structure.*second))
              .c_str());
      text += line;
    }
    text += "\n";
  };
  counts("runs (shadow, edge)", &NeighbourhoodStructure::shadow_runs,
         &NeighbourhoodStructure::edge_runs);
  if (std::any_of(rows.begin(), rows.end(), [](const NeighbourhoodRow& row) {
        return row.structure.shadow_side_ends + row.structure.edge_side_ends > 0;
      })) {
    counts("silhouette ends (s, e)", &NeighbourhoodStructure::shadow_side_ends,
           &NeighbourhoodStructure::edge_side_ends);
  }
  if (real_frames.size() > 1 && !patterns.empty()) {
    std::snprintf(line, sizeof(line),
                  "  over real frames 1-%zu and %zu pattern%s: real mean (min-max), SL mean "
                  "(min-max), SL/real of the means%s\n",
                  real_frames.size(), patterns.size(), patterns.size() > 1 ? "s" : "",
                  other_grid_patterns.empty() ? ""
                  : other_grid_is_ir
                      ? "; then SL matched on the IR camera's grid and registered: mean "
                        "(min-max), /real"
                      : "; then SL matched on the delivered grid (the shortcut): mean (min-max), "
                        "/real");
    text += line;
    for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
      if (!measured(statistic)) continue;
      const ValueSpread r = SpreadOf(statistic, real_frames, real.pixel_scale);
      const ValueSpread sl = SpreadOf(statistic, patterns, 1.0);
      std::snprintf(line, sizeof(line), "  %-24s %8.2f (%.2f-%.2f) %8.2f (%.2f-%.2f) %8.2f",
                    statistic.label, r.mean, r.min, r.max, sl.mean, sl.min, sl.max,
                    sl.mean / r.mean);
      text += line;
      if (!other_grid_patterns.empty()) {
        const ValueSpread other = SpreadOf(statistic, other_grid_patterns, 1.0);
        std::snprintf(line, sizeof(line), " %8.2f (%.2f-%.2f) %8.2f", other.mean, other.min,
                      other.max, other.mean / r.mean);
        text += line;
      }
      text += "\n";
    }
  }
  return text;
}

std::string SensorCheckReport::FormatAnchors() const {
  if (anchors.empty() || like_for_like.empty()) return "";
  struct Table {
    const char* name;
    const std::vector<NeighbourhoodStructure>* real;
    const std::vector<NeighbourhoodStructure>* structured;
    std::vector<NeighbourhoodStructure> SensorCheckReport::AnchorRows::*rows;
  };
  const Table tables[] = {
      {"near", &real_near, &pattern_near, &SensorCheckReport::AnchorRows::near},
      {"away", &real_away, &pattern_away, &SensorCheckReport::AnchorRows::away},
      {"desk", &real_desk, &pattern_desk, &SensorCheckReport::AnchorRows::desk}};
  const double real_scale = like_for_like.front().pixel_scale;
  char line[200];
  std::snprintf(line, sizeof(line),
                "\nthe anchors (sim/anchor_noise.h) on the view's render without the sensor's "
                "holes, %zu noise seeds each: mean over seeds / mean over the real frames, beside "
                "structured light's over its patterns\n",
                anchors.front().near.size());
  std::string text = line;
  std::snprintf(line, sizeof(line), "%-24s", "");
  text += line;
  for (const Table& table : tables) {
    if (table.real->empty() || (anchors.front().*table.rows).empty()) continue;
    std::snprintf(line, sizeof(line), "  %s: %8s", table.name, "SL");
    text += line;
    for (const AnchorRows& anchor : anchors) {
      std::snprintf(line, sizeof(line), " %10s", anchor.name.c_str());
      text += line;
    }
  }
  text += "   goal\n";
  for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
    std::snprintf(line, sizeof(line), "%-24s", statistic.label);
    text += line;
    for (const Table& table : tables) {
      if (table.real->empty() || (anchors.front().*table.rows).empty()) continue;
      std::snprintf(line, sizeof(line), "  %*s %8.2f",
                    static_cast<int>(std::strlen(table.name)) + 1, "",
                    RatioOfMeans(statistic, *table.structured, *table.real, real_scale));
      text += line;
      for (const AnchorRows& anchor : anchors) {
        std::snprintf(line, sizeof(line), " %10.2f",
                      RatioOfMeans(statistic, anchor.*table.rows, *table.real, real_scale));
        text += line;
      }
    }
    text += "   0.8-1.2\n";
  }
  return text;
}

namespace {

// The statistics of the small-patch table (SensorCheckReport::view_patches).
struct PatchStatistic {
  const char* label;
  const char* key;  // in sensor_check.json
  double (*value)(const ErrorStructure&);
};
double FirstLag(const std::vector<double>& autocorrelation) {
  return autocorrelation.empty() ? std::numeric_limits<double>::quiet_NaN() : autocorrelation[0];
}
constexpr PatchStatistic kPatchStatistics[] = {
    {"small-patch noise / model", "noise_over_model",
     [](const ErrorStructure& s) { return s.noise_over_model; }},
    {"autocorrelation, lag 1", "autocorrelation_lag_1",
     [](const ErrorStructure& s) { return FirstLag(s.autocorrelation); }},
    {"... along the rows", "autocorrelation_lag_1_along_rows",
     [](const ErrorStructure& s) { return FirstLag(s.autocorrelation_along_rows); }},
    {"... along the columns", "autocorrelation_lag_1_along_columns",
     [](const ErrorStructure& s) { return FirstLag(s.autocorrelation_along_columns); }},
    {"correlation length [px]", "correlation_length_px",
     [](const ErrorStructure& s) { return s.correlation_length_px; }},
    {"planar windows", "windows",
     [](const ErrorStructure& s) { return static_cast<double>(s.patches); }},
};

ValueSpread SpreadOf(const PatchStatistic& statistic, const std::vector<ErrorStructure>& draws) {
  std::vector<double> values;
  for (const ErrorStructure& s : draws) values.push_back(statistic.value(s));
  return SpreadOfValues(values);
}

}  // namespace

std::string SensorCheckReport::FormatViewPatches() const {
  if (view_patches.empty()) return "";
  const PatchRow& real = view_patches.front();
  std::string text =
      "\nlike for like, the view's small planar patches (9 x 9 windows; every frame on the "
      "rendered sensor's pixel grid over the real\ncamera's field of view): mean over the real "
      "frames, patterns or seeds (min-max), and its ratio to the real frames' mean\n";
  char line[200];
  std::snprintf(line, sizeof(line), "%-27s", "");
  text += line;
  for (const PatchRow& row : view_patches) {
    std::snprintf(line, sizeof(line), " %27s",
                  (row.name + " (" + std::to_string(row.draws.size()) + ")").c_str());
    text += line;
  }
  text += "\n";
  for (const PatchStatistic& statistic : kPatchStatistics) {
    std::snprintf(line, sizeof(line), "%-27s", statistic.label);
    text += line;
    const ValueSpread r = SpreadOf(statistic, real.draws);
    for (const PatchRow& row : view_patches) {
      const ValueSpread v = SpreadOf(statistic, row.draws);
      if (&row == &real) {
        std::snprintf(line, sizeof(line), " %12.3f (%.3f-%.3f)", v.mean, v.min, v.max);
      } else {
        std::snprintf(line, sizeof(line), " %8.3f (%.2f-%.2f) %5.2f", v.mean, v.min, v.max,
                      v.mean / r.mean);
      }
      text += line;
    }
    text += "\n";
  }
  return text;
}

nlohmann::json SensorCheckReport::ToJson() const {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : columns) j.push_back(sim::ToJson(c));
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& c : rendered_frames) frames.push_back(sim::ToJson(c));
  nlohmann::json error_structure = nlohmann::json::object();
  for (size_t k = 0; k < structures.size(); ++k) {
    error_structure[structure_names[k]] = sim::ToJson(structures[k]);
  }
  auto temporal_rows = [](const std::vector<TemporalRow>& rows) {
    nlohmann::json out = nlohmann::json::array();
    for (const TemporalRow& row : rows) {
      nlohmann::json lags = nlohmann::json::array();
      for (size_t k = 0; k < row.lags.size(); ++k) {
        nlohmann::json lag = {{"lag_frames", kTemporalLags[k]},
                              {"rho", row.lags[k].rho},
                              {"windows", row.lags[k].patches}};
        if (k < row.surface_lags.size()) {
          lag["following_the_surface"] = {{"rho", row.surface_lags[k].rho},
                                          {"windows", row.surface_lags[k].patches}};
        }
        lags.push_back(lag);
      }
      out.push_back({{"sequence", row.name}, {"lags", lags}});
    }
    return out;
  };
  const nlohmann::json temporal_json = temporal_rows(temporal);
  auto neighbourhoods = [](const std::vector<NeighbourhoodRow>& rows) {
    nlohmann::json like = nlohmann::json::array();
    for (const NeighbourhoodRow& row : rows) {
      const NeighbourhoodStructure& n = row.structure;
      like.push_back({{"frame", row.name},
                      {"pixel_scale", row.pixel_scale},
                      {"pixels", n.pixels},
                      {"missing_share", n.missing_share},
                      {"interior_pixels", n.interior_pixels},
                      {"interior_missing_share", n.interior_missing_share},
                      {"shadow_band_px", n.shadow_band_px * row.pixel_scale},
                      {"edge_band_px", n.edge_band_px * row.pixel_scale},
                      {"shadow_band_across_px", n.shadow_band_across_px * row.pixel_scale},
                      {"edge_band_across_px", n.edge_band_across_px * row.pixel_scale},
                      {"shadow_side_bleed_px", n.shadow_side_bleed_px * row.pixel_scale},
                      {"edge_side_bleed_px", n.edge_side_bleed_px * row.pixel_scale},
                      {"shadow_side_erosion_px", n.shadow_side_erosion_px * row.pixel_scale},
                      {"edge_side_erosion_px", n.edge_side_erosion_px * row.pixel_scale},
                      {"shadow_runs", n.shadow_runs},
                      {"edge_runs", n.edge_runs},
                      {"shadow_side_ends", n.shadow_side_ends},
                      {"edge_side_ends", n.edge_side_ends}});
    }
    return like;
  };
  // Over speckle patterns: each pattern's statistics and each ratio's spread.
  auto over_patterns = [&](const std::vector<NeighbourhoodRow>& rows,
                           const std::vector<NeighbourhoodStructure>& patterns) {
    nlohmann::json per_pattern = nlohmann::json::array();
    for (size_t k = 0; k < patterns.size(); ++k) {
      per_pattern.push_back(
          neighbourhoods(std::vector<NeighbourhoodRow>{{"view, SL", 1.0, patterns[k]}})[0]);
      per_pattern.back()["pattern_seed"] = pattern_seeds[k];
    }
    nlohmann::json ratios = nlohmann::json::object();
    for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
      const NeighbourhoodRow& real = rows.front();
      const ValueSpread r =
          SpreadOf(statistic, patterns, 1.0, statistic.value(real.structure, real.pixel_scale));
      ratios[statistic.key] = {{"mean", r.mean}, {"sd", r.sd}, {"min", r.min}, {"max", r.max}};
    }
    return nlohmann::json{{"patterns", per_pattern}, {"ratio_to_real", ratios}};
  };
  // The real frames, and the ratio of the mean over patterns to the mean over real frames.
  auto over_real_frames = [&](const std::vector<NeighbourhoodRow>& rows,
                              const std::vector<NeighbourhoodStructure>& real_frames,
                              const std::vector<NeighbourhoodStructure>& patterns) {
    const NeighbourhoodRow& real = rows.front();
    nlohmann::json per_frame = nlohmann::json::array();
    for (size_t k = 0; k < real_frames.size(); ++k) {
      per_frame.push_back(neighbourhoods(std::vector<NeighbourhoodRow>{
          {real.name.substr(0, real.name.rfind(" frame ")) + " frame " + std::to_string(k + 1),
           real.pixel_scale, real_frames[k]}})[0]);
    }
    nlohmann::json ratios = nlohmann::json::object();
    for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
      ratios[statistic.key] = RatioOfMeans(statistic, patterns, real_frames, real.pixel_scale);
    }
    return nlohmann::json{{"frames", per_frame}, {"ratio_of_means", ratios}};
  };
  nlohmann::json result = {{"columns", j},
                           {"rendered_frames", frames},
                           {"error_structure", error_structure},
                           {"temporal_correlation", temporal_json},
                           {"like_for_like", neighbourhoods(like_for_like)},
                           {"like_for_like_away", neighbourhoods(like_for_like_away)}};
  if (!pattern_near.empty()) {
    result["like_for_like_patterns"] = over_patterns(like_for_like, pattern_near);
  }
  if (!pattern_away.empty()) {
    result["like_for_like_away_patterns"] = over_patterns(like_for_like_away, pattern_away);
  }
  if (!view_temporal.empty()) result["view_temporal_correlation"] = temporal_rows(view_temporal);
  if (real_near.size() > 1 && !pattern_near_other_grid.empty()) {
    result["like_for_like_other_grid_real_frames"] =
        over_real_frames(like_for_like, real_near, pattern_near_other_grid);
  }
  if (!pattern_near_other_grid.empty()) {
    result["like_for_like_other_grid_patterns"] =
        over_patterns(like_for_like, pattern_near_other_grid);
    result["other_grid"] = other_grid_is_ir ? "ir" : "delivered";
  }
  if (real_near.size() > 1 && !pattern_near.empty()) {
    result["like_for_like_real_frames"] = over_real_frames(like_for_like, real_near, pattern_near);
  }
  if (real_away.size() > 1 && !pattern_away.empty()) {
    result["like_for_like_away_real_frames"] =
        over_real_frames(like_for_like_away, real_away, pattern_away);
  }
  if (!anchors.empty()) {
    nlohmann::json out = nlohmann::json::array();
    for (const AnchorRows& anchor : anchors) {
      nlohmann::json entry = {{"model", anchor.name}};
      for (const auto& [key, rows, real] : {std::tuple{"near", &anchor.near, &real_near},
                                            std::tuple{"away", &anchor.away, &real_away},
                                            std::tuple{"desk_edge", &anchor.desk, &real_desk}}) {
        if (rows->empty()) continue;
        nlohmann::json seeds = nlohmann::json::array();
        for (const NeighbourhoodStructure& n : *rows) {
          seeds.push_back(neighbourhoods(std::vector<NeighbourhoodRow>{{anchor.name, 1.0, n}})[0]);
        }
        entry[key] = seeds;
        if (real->size() > 1 && !like_for_like.empty()) {
          nlohmann::json ratios = nlohmann::json::object();
          for (const NeighbourhoodStatistic& statistic : kNeighbourhoodStatistics) {
            ratios[statistic.key] =
                RatioOfMeans(statistic, *rows, *real, like_for_like.front().pixel_scale);
          }
          entry[std::string(key) + "_ratio_of_means"] = ratios;
        }
      }
      out.push_back(entry);
    }
    result["like_for_like_anchors"] = out;
  }
  if (!view_patches.empty()) {
    // Per row its draws' structures, the means and the ratios of the means to the real frames'.
    nlohmann::json out = nlohmann::json::array();
    std::vector<double> real_means;
    for (const PatchStatistic& statistic : kPatchStatistics) {
      real_means.push_back(SpreadOf(statistic, view_patches.front().draws).mean);
    }
    for (const PatchRow& row : view_patches) {
      nlohmann::json draws = nlohmann::json::array();
      for (const ErrorStructure& s : row.draws) draws.push_back(sim::ToJson(s));
      nlohmann::json means = nlohmann::json::object(), ratios = nlohmann::json::object();
      for (size_t k = 0; k < std::size(kPatchStatistics); ++k) {
        const double mean = SpreadOf(kPatchStatistics[k], row.draws).mean;
        means[kPatchStatistics[k].key] = mean;
        ratios[kPatchStatistics[k].key] = mean / real_means[k];
      }
      out.push_back(
          {{"source", row.name}, {"draws", draws}, {"mean", means}, {"ratio_of_means", ratios}});
    }
    result["like_for_like_small_patches"] = out;
  }
  auto step_law_rows = [](const std::vector<StepLawRow>& rows) {
    auto number = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); };
    nlohmann::json out = nlohmann::json::array();
    for (const StepLawRow& row : rows) {
      out.push_back({{"frames", row.name},
                     {"fx_px", row.fx_px},
                     {"frame_count", row.frames},
                     {"shadow", sim::ToJson(row.shadow)},
                     {"edge", sim::ToJson(row.edge)},
                     {"shadow_small_steps", sim::ToJson(row.shadow_small)},
                     {"edge_small_steps", sim::ToJson(row.edge_small)},
                     {"shadow_geometry_m", number(row.shadow_geometry_m)},
                     {"edge_geometry_m", number(row.edge_geometry_m)}});
    }
    return out;
  };
  result["step_laws"] = step_law_rows(step_laws);
  if (!view_step_laws.empty()) result["view_step_laws"] = step_law_rows(view_step_laws);
  if (!like_for_like_desk.empty()) {
    result["like_for_like_desk_edge"] = neighbourhoods(like_for_like_desk);
    result["like_for_like_desk_edge_patterns"] = over_patterns(like_for_like_desk, pattern_desk);
    if (real_desk.size() > 1) {
      result["like_for_like_desk_edge_real_frames"] =
          over_real_frames(like_for_like_desk, real_desk, pattern_desk);
    }
  }
  return result;
}

void WriteSensorCheck(const SensorCheckReport& report, const std::filesystem::path& out) {
  EnsureDirectory(out);
  WriteFileAtomically(out / "sensor_check.json", report.ToJson().dump(2) + "\n");
  // Real (TUM) and rendered depth side by side, for a look (the TUM frame is 640 x 480 too).
  if (static_cast<size_t>(report.width) * report.height == report.rendered_depth_m[0].size()) {
    WriteRgbPng(out / "sensor_check.png",
                DepthSideBySide({&report.tum_depth_m, &report.rendered_depth_m[0],
                                 &report.rendered_depth_m[1]},
                                report.width, report.height));
  }
  if (report.view_width > 0) {
    WriteRgbPng(out / "sensor_check_view.png",
                DepthSideBySide({&report.view_depth_m[0], &report.view_depth_m[1],
                                 &report.view_depth_m[2]},
                                report.view_width, report.view_height));
    WriteRgbPng(out / "sensor_check_view_native.png",
                DepthSideBySide({&report.native_view_depth_m[0], &report.native_view_depth_m[1],
                                 &report.native_view_depth_m[2]},
                                report.native_view_width, report.native_view_height));
  }
}

}  // namespace mmh::sim
