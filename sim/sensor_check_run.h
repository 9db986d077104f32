// `mmh sensor-check`: real Kinect v1 depth frames (TUM, NYU; SUN's sensor differs and is shown for
// contrast) beside frames the sensor model renders of the table-top scene in both of its modes,
// the statistical model and structured light (docs/sensor.md). The statistics are
// sim/sensor_check.h's and sim/error_structure.h's; this file runs them over both kinds of frame.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/error_structure.h"
#include "sim/render_session.h"
#include "sim/sensor_check.h"
#include "sim/step_law.h"

namespace mmh::sim {

// Frames of one real view over time (a recording of a nearly static scene), for the temporal
// structure of its errors: depth [m] width x height row-major, at least kTemporalLags.back() + 1
// frames.
struct DepthSequence {
  std::string name;
  int width = 0, height = 0;
  PinholeIntrinsics intrinsics;
  std::vector<std::vector<float>> depth_m;
};

// A real frame and the same view rendered (docs/sensor.md, "Like for like"): issue 23's
// comparable table-top scene. The view's render config places the camera where the real one
// stood and the object, with its real shape as the proxy, where the truth puts it
// (tests/data/real/ycbv/views, render_real_view.py); render.trajectory's first pose is the real
// frame's.
struct RealView {
  std::string name;
  int width = 0, height = 0;
  PinholeIntrinsics intrinsics;
  std::vector<float> depth_m;  // the real frame [m], width x height row-major, 0 = missing
  std::vector<uint8_t> mask;   // the object's pixels in it (its label image), non-zero = object
  // The other labelled objects' pixels (non-zero); empty: none known. The view places those it
  // knows as scene.objects (the mug and the foam brick beside the gelatin box).
  std::vector<uint8_t> others;
  RenderConfig config;
  // Speckle patterns the structured-light view is rendered with: the config's pattern_seed and
  // the next patterns - 1 seeds. The device has one fixed pattern, the model one random draw of
  // it, and the like-for-like statistics hang on the draw (docs/sensor.md, "Over speckle
  // patterns"): their mean and spread over draws are what to compare.
  int patterns = 1;
  // The recording's frames 2, 3, ... of the same view (ReadRealView's `frames`), for the real
  // side's spread: the real device's errors change from frame to frame (the camera moves by a
  // few millimetres), the rendered view is compared at the first frame's poses.
  struct Frame {
    std::vector<float> depth_m;
    std::vector<uint8_t> mask, others;
  };
  std::vector<Frame> later_frames;
};

// The neighbourhood of the object compared (AnalyseNeighbourhood): its mask grown by this many
// pixels at the rendered sensor's focal length (in proportion at the real frame's).
inline constexpr int kNeighbourhoodRadiusPx = 10;
// The object's interior compared (MissingInside): its mask shrunk by this many pixels at the
// rendered sensor's focal length (in proportion at the real frame's), clear of what the outline
// does (it erodes by under a pixel, docs/sensor.md, "Inside the objects").
inline constexpr int kInteriorErosionPx = 5;

// Frame lags of the temporal correlation (AnalyseTemporalCorrelation against the first frame).
inline constexpr int kTemporalLags[] = {1, 2, 4};

// The step law (sim/step_law.h) of one sensor's frames, pooled: what geometry their missing
// bands beside depth edges imply.
struct StepLawRow {
  std::string name;
  double fx_px = 0;  // the focal length of the camera that delivers the frames
  int frames = 0;
  // A rendered sensor's own geometry [m]: the projector's distance from the camera that delivers
  // the image (baseline - ir_camera_offset when registered, the baseline when not) and the IR
  // camera's (ir_camera_offset, 0 when not registered); NaN for real frames.
  double shadow_geometry_m = 0, edge_geometry_m = 0;
  // Over all steps, and over the small ones alone (kSmallStepPxPerM).
  StepLaw shadow, edge, shadow_small, edge_small;
};

// The step laws' ranges of x at 525 px (scaled with each row's focal length, so that every row
// cuts at the same inverse-depth step): from 40 px / m (2 px of shadow at 5 cm), and the small
// steps up to 200 px / m (10 px at 5 cm; the objects on a table top, where the desk's edge gives
// ~600).
inline constexpr double kStepLawFocalPx = 525;
inline constexpr double kSmallStepPxPerM = 200;

struct SensorCheckReport {
  // TUM real, NYU real, SUN real, then the first frame of each rendered mode.
  std::vector<SensorStatistics> columns;
  // Every rendered frame: the statistical mode's, then structured light's.
  std::vector<SensorStatistics> rendered_frames;
  // The error structure of TUM, NYU, the kinect_sequence's first frame (when given) and each
  // mode's first frame, by name.
  std::vector<std::string> structure_names;
  std::vector<ErrorStructure> structures;
  // Structured light's first frame: missing pixels by the sensor's cause against the causes the
  // depth-image rules name.
  std::string cause_table;
  // Depth [m] of the TUM frame and of each mode's first frame (statistical, structured light),
  // width x height row-major, for the side-by-side picture.
  int width = 0, height = 0;
  std::vector<float> tum_depth_m;
  std::vector<float> rendered_depth_m[2];
  // The temporal correlation of residuals at each of kTemporalLags: the real sequence (when
  // given), then each rendered mode (the demo walk; the windows on the moving proxy rarely count).
  struct TemporalRow {
    std::string name;
    std::vector<TemporalCorrelation> lags;  // one per kTemporalLags
    // The same at the points of the surface rather than the pixels (SurfaceAlignedDepth, with the
    // camera's motion between the frames); empty where the motion is not known.
    std::vector<TemporalCorrelation> surface_lags;
  };
  std::vector<TemporalRow> temporal;
  // The same for the like-for-like view (when a RealView is given): the real view's own frames
  // (the sequence's first, as the real sequence's row in `temporal`, when it has enough), then
  // structured light from a still camera and moved as the real camera moved between the real
  // frames; the real and the moved rows also following the surface.
  std::vector<TemporalRow> view_temporal;
  // The step law of TUM, NYU (its raw frame is the IR camera's: kNyuDepthIntrinsics), the
  // kinect_sequence's frames (when given) and each rendered mode's frames of the demo walk (all
  // `frames`).
  std::vector<StepLawRow> step_laws;
  // With a RealView: its real frames (the first and later_frames), the view rendered statistically
  // and in structured light over its patterns.
  std::vector<StepLawRow> view_step_laws;
  // Like for like (when a RealView is given): the real frame, then the view rendered in each mode
  // (statistical, structured light). pixel_scale turns the row's pixels into the rendered
  // sensor's (its focal length over the row's).
  struct NeighbourhoodRow {
    std::string name;
    double pixel_scale = 1;
    NeighbourhoodStructure structure;
  };
  std::vector<NeighbourhoodRow> like_for_like;
  // The same, away from the other objects: their pixels grown by kNeighbourhoodRadiusPx (in the
  // real frame's proportion) left out of both frames' neighbourhoods (AnalyseNeighbourhood's
  // `excluded`, mapped to the rendered frames by ResampleDepthNearest). Empty without
  // RealView::others.
  std::vector<NeighbourhoodRow> like_for_like_away;
  // The same along the desk's edge, when the view's table top ends in the picture (scene.table_x,
  // table_y, table_yaw_deg): the top's pixels beside the floor's in the exact render grown by
  // kNeighbourhoodRadiusPx, the object's and the other objects' neighbourhoods left out.
  std::vector<NeighbourhoodRow> like_for_like_desk;
  std::vector<NeighbourhoodStructure> pattern_desk, real_desk;
  // The structured-light view over RealView::patterns speckle patterns (the first is the one in
  // like_for_like's last row): per pattern, the neighbourhood near the object and away from the
  // other objects (the latter empty without RealView::others).
  std::vector<uint64_t> pattern_seeds;
  std::vector<NeighbourhoodStructure> pattern_near, pattern_away;
  // The same near the object with the IR image matched on the other grid than the config's
  // (StructuredLightOptions::match_on_ir_grid), per pattern: on the IR camera's own grid with the
  // depth registered to the colour camera as the device's driver does (RegisterDepth), or on the
  // delivered grid (the model's shortcut); what the registration changes at the object's outline
  // (docs/sensor.md, "Matched on the IR camera's grid"). other_grid_is_ir says which.
  std::vector<NeighbourhoodStructure> pattern_near_other_grid;
  bool other_grid_is_ir = true;
  // The real frames (the first is like_for_like's first row), near the object and away from the
  // other objects, in the real frame's pixels (like_for_like's first pixel_scale turns them into
  // the rendered sensor's).
  std::vector<NeighbourhoodStructure> real_near, real_away;
  // Their depth images for sensor_check_view.png (real, statistical, structured light), the
  // rendered ones resampled to the real frame's intrinsics (ResampleDepthNearest): the same scale
  // and field of view.
  int view_width = 0, view_height = 0;
  std::vector<float> view_depth_m[3];
  // The same three on the rendered sensor's pixel grid over the real camera's field of view (the
  // real frame resampled down to it), each pixel shown as 2 x 2 (native_view_width x
  // native_view_height): at the real frame's scale the rendered pixels are blocks and the real
  // frame's, registered to a colour camera of twice the focal length, are not, which tells the
  // frames apart by the resampling instead of the sensor.
  int native_view_width = 0, native_view_height = 0;
  std::vector<float> native_view_depth_m[3];

  // The view's small planar patches like for like (AnalyseErrorStructure's small-patch noise, the
  // residuals' autocorrelation and its length; docs/sensor.md, "Small patches like for like"):
  // every frame on the rendered sensor's pixel grid over the real camera's field of view (the real
  // frames resampled down to it, the rendered ones cut to it), so that both are sampled alike and
  // cover the same part of the scene. One row per source, one structure per draw: the real frames
  // (the first and later_frames), the view rendered statistically, in structured light per
  // pattern (pattern_seeds) and by each anchor per noise seed.
  struct PatchRow {
    std::string name;
    std::vector<ErrorStructure> draws;
  };
  std::vector<PatchRow> view_patches;

  // The published noise models issue 23 names as anchors (sim/anchor_noise.h: ICL-NUIM and
  // simkinect), applied to the exact render: the demo walk's first frame's error structure is in
  // `structures` after the two modes ("anchor ICL-NUIM", "anchor simkinect"); with a RealView, per
  // model and per noise seed (RealView::patterns of them: config.sensor.seed and the next ones),
  // the view's neighbourhoods near the object, away from the other objects (empty without
  // RealView::others) and along the desk's edge (empty without one), and the view's rows in
  // view_temporal from a still camera.
  struct AnchorRows {
    std::string name;
    std::vector<NeighbourhoodStructure> near, away, desk;
  };
  std::vector<AnchorRows> anchors;

  // The tables `mmh sensor-check` prints.
  std::string Format() const;
  std::string FormatLikeForLike() const;
  std::string FormatAnchors() const;
  std::string FormatViewPatches() const;
  std::string FormatStepLaws() const;
  std::string FormatNeighbourhoods(
      const std::string& title, const std::vector<NeighbourhoodRow>& rows,
      const std::vector<NeighbourhoodStructure>& patterns = {},
      const std::vector<NeighbourhoodStructure>& real_frames = {},
      const std::vector<NeighbourhoodStructure>& other_grid_patterns = {}) const;
  // sensor_check.json: columns, rendered_frames, error_structure.
  nlohmann::json ToJson() const;
};

// Reads TUM_depth.png, NYU_depth.pgm and SUN_depth.png from `real_frames` (InputError naming a
// missing or unreadable file) and renders `frames` frames of `config`'s scene (the demo walk) in
// both sensor modes (at least kTemporalLags.back() + 1 for the temporal structure, which the
// statistics of frames beyond `frames` do not enter). `real_sequence`: a real recording's first
// frames for the temporal structure (nullptr: none). `real_view`: a real frame and its view to
// compare like for like (nullptr: none). `kinect_sequence`: more real Kinect v1 frames for the
// step law (nullptr: none).
SensorCheckReport RunSensorCheck(const std::filesystem::path& real_frames,
                                 const RenderConfig& config, int frames,
                                 const DepthSequence* real_sequence = nullptr,
                                 const RealView* real_view = nullptr,
                                 const DepthSequence* kinect_sequence = nullptr);

// Writes sensor_check.json and, when the frames have the same size, sensor_check.png (TUM,
// statistical, structured light side by side) into `out`; with a like-for-like comparison also
// sensor_check_view.png (the real frame, statistical, structured light) and
// sensor_check_view_native.png (the same on the rendered sensor's pixel grid).
void WriteSensorCheck(const SensorCheckReport& report, const std::filesystem::path& out);

}  // namespace mmh::sim
