// Determinism of every subcommand that writes results (issue 21): the same inputs give the same
// bytes across two runs and for --threads 1 and --threads 2. Provenance aside: run.json, and the
// few files that hold wall times or per-thread work counts, named per case below.
//
// Each case runs three times into the same --out path (paths written into outputs then match):
// --threads 1, --threads 2, --threads 2 again (commands without --threads: twice). Inputs are small
// (a few seconds per case in Release).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;

const std::string kSource = MMH_SOURCE_DIR;
const std::string kStory = kSource + "/examples/synthetic_story/";
// What a case's `prepare` returns when its inputs are absent on this machine.
constexpr char kSkip[] = "(skip)";

struct Case {
  std::string name;
  // Makes the case's inputs under `in` and returns the command's arguments; OUT stands for the
  // output (a folder, or a file when `out_is_file`).
  std::function<std::string(const fs::path& in)> prepare;
  bool threads = true;  // the command has --threads
  // Files compared by existence only, by file name: provenance and timings.
  std::set<std::string> skip = {"run.json"};
  bool out_is_file = false;
  // The command writes into an existing folder (mmh report): OUT is first a copy of `in`/target.
  bool in_place = false;
};

// gtest prints a failing case by its name.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// `text` with every OUT replaced by `out`.
std::string WithOut(std::string text, const std::string& out) {
  for (size_t at = text.find("OUT"); at != std::string::npos;
       at = text.find("OUT", at + out.size())) {
    text.replace(at, 3, out);
  }
  return text;
}

// Runs `mmh ARGS` and fails the test (with its output) unless it exits 0.
void MustRun(const std::string& args) {
  const auto r = RunMmh(args + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.output;
}

// Every file under `out` (or `out` itself) by relative path -> bytes; skipped files map to "".
std::map<std::string, std::string> Snapshot(const fs::path& out, const Case& c) {
  std::map<std::string, std::string> files;
  auto add = [&](const fs::path& file, const std::string& rel) {
    const std::string name = file.filename().string();
    if (c.skip.count(name)) {
      files[rel] = "";
      return;
    }
    files[rel] = ReadBytes(file);
  };
  if (fs::is_regular_file(out)) {
    add(out, out.filename().string());
    return files;
  }
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    if (e.is_regular_file()) add(e.path(), fs::relative(e.path(), out).string());
  }
  return files;
}

// The names of the files that differ (or exist in one only), with the first differing byte.
std::string Differences(const std::map<std::string, std::string>& a,
                        const std::map<std::string, std::string>& b) {
  std::string text;
  std::set<std::string> names;
  for (const auto& [n, _] : a) names.insert(n);
  for (const auto& [n, _] : b) names.insert(n);
  for (const std::string& n : names) {
    const auto ia = a.find(n), ib = b.find(n);
    if (ia == a.end() || ib == b.end()) {
      text += "  " + n + ": only in run " + (ia == a.end() ? "2" : "1") + "\n";
    } else if (ia->second != ib->second) {
      size_t k = 0;
      while (k < ia->second.size() && k < ib->second.size() && ia->second[k] == ib->second[k]) ++k;
      text += "  " + n + ": differs from byte " + std::to_string(k) + ": '" +
              ia->second.substr(k, 60) + "' vs '" + ib->second.substr(k, 60) + "'\n";
    }
  }
  return text;
}

class DeterminismTest : public ::testing::TestWithParam<Case> {
 protected:
  // The shipped configs name their stories relative to the project.
  void SetUp() override {
    previous_ = fs::current_path();
    fs::current_path(kSource);
  }
  void TearDown() override { fs::current_path(previous_); }
  fs::path previous_;
};

TEST_P(DeterminismTest, SameBytesAcrossRunsAndThreadCounts) {
  const Case& c = GetParam();
  TempDir dir;
  const fs::path in = dir / "in";
  fs::create_directories(in);
  const std::string args = c.prepare(in);
  if (HasFatalFailure()) return;
  if (args == kSkip) GTEST_SKIP() << "inputs absent on this machine";
  const fs::path out = dir / (c.out_is_file ? "out.glb" : "out");
  const std::vector<std::string> variants =
      c.threads ? std::vector<std::string>{" --threads 1", " --threads 2", " --threads 2"}
                : std::vector<std::string>{"", ""};
  std::vector<std::map<std::string, std::string>> snapshots;
  for (const std::string& variant : variants) {
    fs::remove_all(out);
    if (c.in_place) fs::copy(in / "target", out, fs::copy_options::recursive);
    const std::string command = WithOut(args, out.string()) + variant;
    const auto r = RunMmh(command);
    ASSERT_EQ(r.exit_code, 0) << command << "\n" << r.output;
    snapshots.push_back(Snapshot(out, c));
    ASSERT_FALSE(snapshots.back().empty()) << command;
  }
  for (size_t k = 1; k < snapshots.size(); ++k) {
    EXPECT_TRUE(snapshots[0] == snapshots[k])
        << "run 1 (" << variants[0] << ") and run " << k + 1 << " (" << variants[k] << ") differ:\n"
        << Differences(snapshots[0], snapshots[k]);
  }
}

std::string ComposeArgs(int takes) {
  std::string s = "compose --takes";
  for (int k = 1; k <= takes; ++k) s += " " + kStory + "take_" + std::to_string(k) + ".tum";
  s += " --annotations";
  for (int k = 1; k <= takes; ++k) s += " " + kStory + "take_" + std::to_string(k) + ".csv";
  return s;
}

const std::string kStudy = "study --config " + kSource +
                           "/configs/study_soldier.json --set run.fidelity=fast "
                           "--set study.animators=6";

// A rendered take of 20 frames (a TUM RGB-D folder with model.ply) under in/take.
void RenderTake(const fs::path& in) {
  MustRun("render --set render.frames=20 --out " + (in / "take").string());
}

void WriteText(const fs::path& path, const json& j) { test_util::WriteText(path, j.dump(2)); }

// A sweep spec of 4 compose cells.
json ComposeSweepSpec() {
  return {
      {"command", "compose"},
      {"inputs",
       {{"takes", {kStory + "take_1.tum", kStory + "take_2.tum", kStory + "take_3.tum"}},
        {"annotations", {kStory + "take_1.csv", kStory + "take_2.csv", kStory + "take_3.csv"}}}},
      {"axes",
       {{{"key", "montage.labelling.mu"}, {"values", {10, 1000}}},
        {{"key", "montage.labelling.min_segment_length"}, {"values", {0, 60}}}}},
      {"metrics",
       {{{"name", "total_cost"}, {"file", "summary.json"}, {"key", "total_cost"}},
        {{"name", "segments"}, {"file", "summary.json"}, {"key", "segments"}}}}};
}

const std::vector<Case>& Cases() {
  static const std::vector<Case> cases = {
      {.name = "compose", .prepare = [](const fs::path&) { return ComposeArgs(3) + " --out OUT"; }},
      // A second object layered on the first: two takes made of the first's montage, moved (as
      // in tests/report/report_cli_test.cc).
      {.name = "compose_layers",
       .prepare =
           [](const fs::path& in) {
             MustRun(ComposeArgs(3) + " --no-glb --out " + (in / "base").string());
             const Trajectory montage = ReadTum(in / "base" / "montage.tum");
             std::string takes, annotations;
             for (int k = 1; k <= 2; ++k) {
               Trajectory take = montage;
               std::string csv = "timestamp,value\n";
               for (std::size_t i = 0; i < take.size(); ++i) {
                 take.poses[i].translation.x() += 0.1 * k;
                 csv += FormatNumber(take.timestamps[i]) + "," +
                        FormatNumber(3.0 * std::sin(0.01 * k * static_cast<double>(i))) + "\n";
               }
               const fs::path file = in / ("layer_" + std::to_string(k));
               WriteTum(file.string() + ".tum", take);
               test_util::WriteText(file.string() + ".csv", csv);
               takes += " " + file.string() + ".tum";
               annotations += " " + file.string() + ".csv";
             }
             return ComposeArgs(3) + " --layer-takes" + takes + " --layer-annotations" +
                    annotations + " --layer-names cube --out OUT";
           }},
      // render_summary.json counts the rays each thread cast (they depend on the split).
      {.name = "render",
       .prepare =
           [](const fs::path&) {
             return std::string(
                 "render --set render.frames=20 --set render.fakenect=true "
                 "--set render.bop=true --out OUT");
           },
       .skip = {"run.json", "render_summary.json"}},
      {.name = "run",
       .prepare =
           [](const fs::path&) {
             return "run --config " + kSource +
                    "/configs/soldier.json --set render.frames=61 --out OUT";
           },
       .skip = {"run.json", "timings.csv"}},
      {.name = "study", .prepare = [](const fs::path&) { return kStudy + " --out OUT"; }},
      {.name = "study_replicates",
       .prepare =
           [](const fs::path&) {
             return kStudy + " --set study.animators=4 --replicates 3 --out OUT";
           }},
      {.name = "track",
       .prepare =
           [](const fs::path& in) {
             RenderTake(in);
             const fs::path take = in / "take";
             return "track --input " + take.string() + " --model " + (take / "model.ply").string() +
                    " --out OUT";
           }},
      {.name = "eval",
       .prepare =
           [](const fs::path& in) {
             RenderTake(in);
             const fs::path take = in / "take";
             MustRun("track --input " + take.string() + " --model " +
                     (take / "model.ply").string() + " --out " + (in / "tracked").string());
             return "eval --input " + take.string() + " --model " + (take / "model.ply").string() +
                    " --estimate " + (in / "tracked" / "trajectory.tum").string() + " --out OUT";
           },
       .threads = false},
      {.name = "stats",
       .prepare =
           [](const fs::path&) {
             return "stats --input " + kSource + "/examples/study_data --out OUT";
           },
       .threads = false},
      {.name = "check_paper",
       .prepare =
           [](const fs::path&) {
             std::string args = "check-paper --out OUT";
             const fs::path paper = kSource + "/../shared/paper/motionmontage-chi2014.txt";
             if (fs::exists(paper)) args += " --paper " + paper.string();
             return args;
           },
       .threads = false},
      {.name = "export",
       .prepare =
           [](const fs::path&) {
             return "export --trajectory " + kStory + "take_1.tum --model " + kSource +
                    "/configs/proxies/soldier.json --out OUT";
           },
       .threads = false,
       .out_is_file = true},
      {.name = "report_compose",
       .prepare =
           [](const fs::path& in) {
             MustRun(ComposeArgs(3) + " --out " + (in / "target").string());
             return std::string("report OUT");
           },
       .threads = false,
       .in_place = true},
      {.name = "report_study",
       .prepare =
           [](const fs::path& in) {
             MustRun(kStudy + " --out " + (in / "target").string());
             return std::string("report OUT");
           },
       .threads = false,
       .in_place = true},
      {.name = "sweep",
       .prepare =
           [](const fs::path& in) {
             WriteText(in / "spec.json", ComposeSweepSpec());
             return "sweep --jobs 2 --spec " + (in / "spec.json").string() + " --out OUT";
           },
       // A cell's provenance.json is its run.json (command line, host, timings).
       .skip = {"run.json", "provenance.json"}},
      {.name = "regress",
       .prepare =
           [](const fs::path& in) {
             fs::create_directories(in / "baseline");
             WriteText(in / "baseline" / "baseline.json",
                       {{"root", kSource},
                        {"scenarios",
                         {{{"name", "quick"},
                           {"config", "configs/soldier.json"},
                           {"set", {"run.fidelity=\"fast\"", "render.frames=300"}},
                           {"metrics", json::object()}}}}});
             return "regress --baseline " + (in / "baseline").string() + " --out OUT";
           },
       .skip = {"run.json", "timings.csv"}},
      {.name = "calibrate",
       .prepare =
           [](const fs::path& in) {
             // Four cells of one parameter, 2 studies of 5 animators each (as
             // tests/calibrate/calibrate_cli_test.cc).
             WriteText(
                 in / "spec.json",
                 {{"command", "study"},
                  {"config", kSource + "/configs/study_soldier.json"},
                  {"set",
                   {"run.fidelity=\"fast\"", "run.metrics=false", "study.replicates=2",
                    "study.animators=5"}},
                  {"samples",
                   {{"method", "latin_hypercube"},
                    {"count", 4},
                    {"seed", 7},
                    {"axes", {{{"key", "viewer.judgement_noise"}, {"from", 0.02}, {"to", 0.4}}}}}},
                  {"metrics",
                   {{{"name", "h1_mean_m"},
                     {"file", "results.json"},
                     {"key", "analysis.h1.mean_m"}}}}});
             WriteText(in / "targets.json", json::parse(R"({"targets": [
                         {"statistic": "h1_mean_m", "value": 0.65, "role": "fit"},
                         {"statistic": "h3_f", "value": 0.83, "role": "holdout"}]})"));
             MustRun("sweep --jobs 2 --spec " + (in / "spec.json").string() + " --out " +
                     (in / "sweep").string());
             return "calibrate --sweep " + (in / "sweep").string() + " --targets " +
                    (in / "targets.json").string() +
                    " --set calibration.ppc_replicates=4 --set calibration.abc.accept_fraction=0.5"
                    " --out OUT";
           }},
      {.name = "sensor_check",
       .prepare =
           [](const fs::path&) {
             if (!fs::exists(kSource + "/../shared/data/real-rgbd/TUM_depth.png") &&
                 !fs::exists("/work/shared/data/real-rgbd/TUM_depth.png")) {
               return std::string(kSkip);
             }
             return std::string("sensor-check --frames 2 --out OUT");
           }},
  };
  return cases;
}

INSTANTIATE_TEST_SUITE_P(EverySubcommand, DeterminismTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.name;
                         });

}  // namespace
}  // namespace mmh
