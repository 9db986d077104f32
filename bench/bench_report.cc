// Speed and size of the glTF export and the HTML report (issue 22: "a 3 000-frame montage with
// three takes: .glb and report written in under 1 s; the report under 5 MB"). Run from a Release
// build:
//   build/bench/bench_report --benchmark_counters_tabular=true
// MMH_BENCH_REPORT_DIR=DIR keeps the folder and its report.html (scrubbing measured in Chromium).
// Figures and machine are recorded in bench/README.md.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/annotation.h"
#include "core/atomic_file.h"
#include "core/tum_io.h"
#include "montage/compose.h"
#include "report/html_report.h"
#include "report/trajectory_glb.h"
#include "sim/duplo.h"
#include "tools/synthetic_takes.h"

namespace {

namespace fs = std::filesystem;

// A compose folder of three takes of about 3000 frames (as mmh compose writes it), made once.
struct Folder {
  fs::path dir;
  std::vector<mmh::Trajectory> takes;
  mmh::montage::Montage montage;
  Folder() {
    // MMH_BENCH_REPORT_DIR keeps the folder (with report.html) for the browser's measurement
    // (bench/README.md); by default a temporary folder, removed at the end.
    const char* keep = std::getenv("MMH_BENCH_REPORT_DIR");
    keep_ = keep && *keep;
    dir = keep_ ? fs::path(keep)
                : fs::temp_directory_path() / ("mmh_bench_report_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    mmh::synthetic::TakeSetOptions options;
    options.takes = 3;
    options.reference_frames = 3000;
    options.min_frames = 2900;
    options.max_frames = 3100;
    options.seed = 42;
    const auto set = mmh::synthetic::MakeTakeSet(options);
    takes = set.takes;
    montage = mmh::montage::Compose(set.takes, set.annotations, mmh::montage::ComposeOptions());
    nlohmann::json summary = mmh::montage::SummaryToJson(montage.summary, montage.segments);
    for (int l = 0; l < 3; ++l) {
      const std::string name = "take_" + std::to_string(l + 1);
      mmh::WriteTum(dir / (name + ".tum"), set.takes[l]);
      mmh::WriteAnnotationCsv(dir / (name + ".csv"), set.annotations[l]);
      summary["take_files"].push_back((dir / (name + ".tum")).string());
      summary["annotation_files"].push_back((dir / (name + ".csv")).string());
    }
    mmh::WriteTum(dir / "montage.tum", montage.trajectory);
    mmh::WriteFileAtomically(dir / "segments.csv", mmh::montage::SegmentsToCsv(montage.segments));
    mmh::WriteFileAtomically(dir / "timeline.csv", mmh::montage::TimelineToCsv(montage));
    mmh::WriteFileAtomically(dir / "summary.json", summary.dump(2));
  }
  ~Folder() {
    if (!keep_) fs::remove_all(dir);
  }
  bool keep_ = false;
};

Folder& TheFolder() {
  static Folder folder;
  return folder;
}

void WriteMontageGlb(const Folder& f) {
  mmh::report::MontageObject object;
  object.mesh = mmh::sim::BuildDuploMesh(mmh::sim::SoldierProxy());
  object.montage = f.montage.trajectory;
  object.takes = f.takes;
  object.warps = f.montage.warps;
  object.marker_frames = {500, 1500};
  mmh::report::WriteGlb(f.dir / "montage.glb", mmh::report::MontageScene({object}));
}

// montage.glb (the Soldier, the montage, 3 takes warped and recorded, 2 markers).
void BM_MontageGlb(benchmark::State& state) {
  const Folder& f = TheFolder();
  for (auto _ : state) WriteMontageGlb(f);
  state.counters["glb_MB"] = static_cast<double>(fs::file_size(f.dir / "montage.glb")) / 1e6;
}
BENCHMARK(BM_MontageGlb)->Unit(benchmark::kMillisecond);

// report.html of the folder (reads the takes, DTW images, inlines montage.glb and the bundle).
void BM_Report(benchmark::State& state) {
  const Folder& f = TheFolder();
  WriteMontageGlb(f);
  mmh::report::ReportSummary summary;
  for (auto _ : state) summary = mmh::report::WriteReport(f.dir);
  state.counters["report_MB"] = static_cast<double>(summary.bytes) / 1e6;
}
BENCHMARK(BM_Report)->Unit(benchmark::kMillisecond);

// Both, as `mmh compose` followed by `mmh report` add them.
void BM_GlbAndReport(benchmark::State& state) {
  const Folder& f = TheFolder();
  for (auto _ : state) {
    WriteMontageGlb(f);
    mmh::report::WriteReport(f.dir);
  }
}
BENCHMARK(BM_GlbAndReport)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
