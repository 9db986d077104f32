// Speed of the synthetic Kinect (issue: full 640x480 depth + colour frames of the Soldier scene,
// noise and shadows included: at least 200 frames/s fully re-rendered, at least 1000 frames/s when
// only the proxy, the hand and the slider block move). Run from a Release build:
//   build/bench/bench_sensor --benchmark_counters_tabular=true
// Figures and machine are recorded in bench/README.md.
#include <benchmark/benchmark.h>

#include <memory>

#include "sim/render_session.h"

namespace {

using mmh::sim::RenderMode;

struct Setup {
  mmh::sim::RenderConfig config;
  std::unique_ptr<mmh::sim::TableTopScene> scene;
  std::unique_ptr<mmh::sim::KinectSensor> sensor;
};

Setup& SoldierScene() {
  static Setup setup = [] {
    Setup s;
    s.config.scene.props = mmh::sim::TableProps::kCastle;
    s.scene =
        std::make_unique<mmh::sim::TableTopScene>(s.config, mmh::sim::LoadProxyModel("", 1.0));
    s.sensor = std::make_unique<mmh::sim::KinectSensor>(s.config.sensor, &s.scene->scene(),
                                                        s.scene->table_T_camera());
    return s;
  }();
  return setup;
}

// One frame per iteration of the demo walk: scene update (instances) + render. arg: 0 incremental,
// 1 full.
void BM_SensorFrame(benchmark::State& state) {
  Setup& s = SoldierScene();
  const RenderMode mode = state.range(0) == 0 ? RenderMode::kIncremental : RenderMode::kFull;
  mmh::RgbdFrame frame;
  s.sensor->Render(0, mode, &frame);  // builds the static cache outside the timing
  s.sensor->ResetTimings();
  int i = 0;
  for (auto _ : state) {
    const double t = i / 30.0;
    s.scene->SetFrame(s.config.motion.TableTProxy(t), s.config.motion.SliderValue(t));
    s.sensor->Render(i, mode, &frame);
    benchmark::DoNotOptimize(frame.depth.data());
    ++i;
  }
  const auto& t = s.sensor->timings();
  const double n = static_cast<double>(t.frames);
  state.counters["fps"] = benchmark::Counter(static_cast<double>(i), benchmark::Counter::kIsRate);
  state.counters["rays/frame"] = static_cast<double>(t.rays) / n;
  state.counters["rays/s"] =
      benchmark::Counter(static_cast<double>(t.rays), benchmark::Counter::kIsRate);
  const double total = t.cast + t.shade + t.occlusion + t.noise;
  state.counters["cast%"] = 100 * t.cast / total;
  state.counters["shade%"] = 100 * t.shade / total;
  state.counters["occlusion%"] = 100 * t.occlusion / total;
  state.counters["noise%"] = 100 * t.noise / total;
}
BENCHMARK(BM_SensorFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
