// The proxy tracker's speed and accuracy on a simulated take (640x480, full Kinect noise, the hand
// holding the proxy, the demo walk), beside PCL's IterativeClosestPointWithNormals on the same
// segmented points (track/internal/pcl_icp_baseline.h). One core: the tracker is sequential.
//
//   ./bench_track --benchmark_counters_tabular=true
//
// items_per_second is frames per second; the counters give the accuracy against the ground truth
// (median rotation [deg] and translation [mm] errors, share of frames within 5 deg and 1 cm).
#include <benchmark/benchmark.h>

#include <optional>
#include <tuple>
#include <vector>

#include "core/config.h"
#include "core/mesh_io.h"
#include "metrics/tracking_metrics.h"
#include "tests/test_meshes.h"
#include "tests/track/sim_take.h"
#include "track/internal/pcl_icp_baseline.h"
#include "track/proxy_model.h"
#include "track/proxy_tracker.h"
#include "track/segmentation.h"
#include "track/recording.h"
#include "track/table_plane.h"
#include "track/track_session.h"

namespace mmh::track {
namespace {

constexpr int kFrames = 150;

struct Take {
  std::vector<RgbdFrame> frames;
  std::vector<Rigid3> truth;
  TriangleMesh model;
  TrackSetup setup;
};

Take RenderTake(test_take::SimTake& sim) {
  Take t;
  for (int i = 0; i < kFrames; ++i) {
    Rigid3 camera_T_proxy;
    t.frames.push_back(sim.Render(i, &camera_T_proxy));
    t.truth.push_back(camera_T_proxy);
  }
  t.model = sim.model();
  t.setup = sim.Setup();
  return t;
}

// The demo walk.
const Take& GetTake() {
  static const Take take = [] {
    test_take::SimTake sim;
    return RenderTake(sim);
  }();
  return take;
}

// The first frames of a Soldier story take (participant 0, take 0: marching in front of the
// castle, seen from the side, with the checks and detections that view costs).
const Take& GetStoryTake() {
  static const Take take = [] {
    int frames = 0;
    test_take::SimTake sim = test_take::SoldierStorySession(
        MMH_BENCH_SOURCE_DIR, 0, 0, sim::RenderSession::kRecording, &frames);
    return RenderTake(sim);
  }();
  return take;
}

void SetAccuracy(benchmark::State& state, const Take& take,
                 const std::vector<std::optional<Rigid3>>& estimates) {
  const auto points = metrics::MetricPoints(take.model);
  const metrics::PoseErrorOptions options;
  const auto errors = metrics::ComputePoseErrors(estimates, take.truth, points, options);
  const auto summary = metrics::SummarizeTracking(errors, metrics::Diameter(points), options);
  state.counters["rot_deg"] = summary.median_rotation_deg;
  state.counters["trans_mm"] = summary.median_translation * 1000;
  state.counters["within_5deg_1cm"] = summary.success_rate;
  state.counters["ADD_mm"] = summary.mean_add * 1000;
  state.counters["ADD-S_mm"] = summary.mean_adds * 1000;
}

// The whole tracker per frame: segmentation, prediction, ICP, verification (the table plane and the
// first detection included, amortised over the take).
void TrackTake(benchmark::State& state, const Take& take) {
  std::vector<std::optional<Rigid3>> estimates;
  size_t grid_bytes = 0;
  for (auto _ : state) {
    state.PauseTiming();
    ProxyTracker tracker(take.model, "soldier", take.setup, ProxyTrackerOptions());
    grid_bytes = tracker.model().grid_bytes();
    estimates.clear();
    state.ResumeTiming();
    for (const RgbdFrame& frame : take.frames) {
      const TrackFrameResult r = tracker.Track(frame);
      estimates.push_back(r.status == TrackStatus::kLost ? std::nullopt
                                                         : std::optional<Rigid3>(r.camera_T_proxy));
    }
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
  SetAccuracy(state, take, estimates);
  state.counters["grid_MB"] = grid_bytes / 1e6;  // the model's closest-point grid
}
void BM_ProxyTracker(benchmark::State& state) { TrackTake(state, GetTake()); }
BENCHMARK(BM_ProxyTracker)->Unit(benchmark::kMillisecond);
void BM_ProxyTrackerStory(benchmark::State& state) { TrackTake(state, GetStoryTake()); }
BENCHMARK(BM_ProxyTrackerStory)->Unit(benchmark::kMillisecond);

// Segmentation alone (play volume, background model, skin, connected components).
void BM_Segmentation(benchmark::State& state) {
  const Take& take = GetTake();
  std::string why;
  const auto plane =
      EstimateTablePlane(take.frames[0], TablePlaneOptions(), take.setup.camera_T_table, &why);
  Segmenter segmenter(SegmentationOptions(), take.setup);
  segmenter.SetTable(TableFrameOnPlane(*plane, take.setup.camera_T_table),
                     take.frames[0].depth_intrinsics);
  Segmentation segmentation;
  for (auto _ : state) {
    for (const RgbdFrame& frame : take.frames) {
      segmenter.Segment(frame, &segmentation);
      benchmark::DoNotOptimize(segmentation.points.data());
    }
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
}
BENCHMARK(BM_Segmentation)->Unit(benchmark::kMillisecond);

// The table plane by RANSAC (once per take).
void BM_TablePlane(benchmark::State& state) {
  const Take& take = GetTake();
  for (auto _ : state) {
    std::string why;
    benchmark::DoNotOptimize(
        EstimateTablePlane(take.frames[0], TablePlaneOptions(), take.setup.camera_T_table, &why));
  }
}
BENCHMARK(BM_TablePlane)->Unit(benchmark::kMillisecond);

// PCL's point-to-plane ICP on the same segmented points, from the true first pose (it has no
// detection), tracking with the same constant-velocity prediction.
void BM_PclIcpWithNormals(benchmark::State& state) {
  const Take& take = GetTake();
  std::vector<std::optional<Rigid3>> estimates;
  for (auto _ : state) {
    state.PauseTiming();
    internal::PclIcpBaseline baseline(take.model, take.setup, internal::PclIcpBaselineOptions(),
                                      take.truth[0]);
    estimates.clear();
    state.ResumeTiming();
    for (const RgbdFrame& frame : take.frames) estimates.push_back(baseline.Track(frame));
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
  SetAccuracy(state, take, estimates);
}
BENCHMARK(BM_PclIcpWithNormals)->Unit(benchmark::kMillisecond);

// Real frames: the committed YCB-Video excerpt (tests/data/real/ycbv, Asus Xtion 640x480), the
// foam brick tracked with configs/track_real.json, all ten frames per repetition (the table plane
// and the first frame's window or detection included): from the ground truth's first pose
// (BM_RealRecording) or from the tracker's own detection (BM_RealRecordingFromDetection: the
// model-sized segments, each with the proxy detection's hypotheses, detection.model_segments), and
// the per-frame cost alone (BM_RealRecordingPerFrame).
//
//   ./bench_track --benchmark_filter=BM_RealRecording
// How a repetition starts: a new tracker from the truth's first pose or from its own detection,
// or the tracker built once (its model and the table plane are per-sequence costs) and only
// re-initialised from the truth (the per-frame cost).
enum class RealStart { kTruth, kDetection, kTruthSameTracker };

void TrackRealRecording(benchmark::State& state, RealStart start) {
  static const auto data = [] {
    const std::string root = std::string(MMH_BENCH_SOURCE_DIR) + "/tests/data/real/ycbv";
    RecordingFrameSource source(root + "/data/0000");
    std::vector<RgbdFrame> frames;
    RgbdFrame frame;
    while (source.Next(&frame)) frames.push_back(frame);
    return std::make_tuple(frames, source.Truth(21), LoadMesh(root + "/models/061_foam_brick.obj"),
                           TrackConfig::FromConfig(Config::Load(
                               std::string(MMH_BENCH_SOURCE_DIR) + "/configs/track_real.json")));
  }();
  const auto& [frames, truth, model, config] = data;
  TrackSetup setup;
  setup.play_area_width = config.track.play_area_width;
  setup.play_area_depth = config.track.play_area_depth;
  int64_t tracked = 0;
  std::optional<ProxyTracker> same;
  if (start == RealStart::kTruthSameTracker) {
    same.emplace(model, "foam brick", setup, config.tracker);
    same->Track(frames.front());  // the table plane
  }
  for (auto _ : state) {
    std::optional<ProxyTracker> fresh;
    if (!same) fresh.emplace(model, "foam brick", setup, config.tracker);
    ProxyTracker& tracker = same ? *same : *fresh;
    if (start != RealStart::kDetection) tracker.Initialize(truth.poses.front());
    for (const RgbdFrame& f : frames) tracked += tracker.Track(f).status == TrackStatus::kTracked;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frames.size()));
  state.counters["tracked_share"] =
      static_cast<double>(tracked) / (state.iterations() * static_cast<double>(frames.size()));
}
void BM_RealRecording(benchmark::State& state) { TrackRealRecording(state, RealStart::kTruth); }
void BM_RealRecordingFromDetection(benchmark::State& state) {
  TrackRealRecording(state, RealStart::kDetection);
}
void BM_RealRecordingPerFrame(benchmark::State& state) {
  TrackRealRecording(state, RealStart::kTruthSameTracker);
}
BENCHMARK(BM_RealRecording)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RealRecordingFromDetection)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RealRecordingPerFrame)->Unit(benchmark::kMillisecond);

// Building the closest-point grid of a large model: a 25 cm cube at the default grid resolution
// (ProxyModelTest.BigModelsAreBuiltAndNonsenseIsRejected checks the result, this the time).
void BM_ProxyModelBuild(benchmark::State& state) {
  const TriangleMesh cube =
      test_util::BoxMesh(Eigen::Vector3d(-0.125, -0.125, 0), Eigen::Vector3d(0.125, 0.125, 0.25));
  for (auto _ : state) {
    const ProxyModel model(cube, ProxyModelOptions(), "cube");
    benchmark::DoNotOptimize(model.grid_bytes());
  }
}
BENCHMARK(BM_ProxyModelBuild)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mmh::track

BENCHMARK_MAIN();
