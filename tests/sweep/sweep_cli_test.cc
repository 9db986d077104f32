// `mmh sweep` as a user runs it, on the bundled synthetic takes: the plan, the local backend
// (same bytes whatever the concurrency and packing, reruns skip complete cells), bad input (exit
// 2, nothing written), failed and SIGKILLed cells, a SIGKILLed sweep restarted.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "sweep/plan.h"
#include "tests/test_util.h"

extern char** environ;

namespace mmh {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test_util::ReadBytes;
using test_util::RunMmh;

// `mmh ARGUMENTS` with one more environment variable (NAME=value).
test_util::CommandResult RunMmhWith(const std::string& arguments, const std::string& variable) {
  setenv(variable.substr(0, variable.find('=')).c_str(),
         variable.substr(variable.find('=') + 1).c_str(), 1);
  const auto result = RunMmh(arguments);
  unsetenv(variable.substr(0, variable.find('=')).c_str());
  return result;
}

std::string Story(int k, const char* ext) {
  return std::string(MMH_SOURCE_DIR) + "/examples/synthetic_story/take_" + std::to_string(k) + ext;
}

json ComposeSpec() {
  json spec = {
      {"command", "compose"},
      {"inputs",
       {{"takes", {Story(1, ".tum"), Story(2, ".tum"), Story(3, ".tum")}},
        {"annotations", {Story(1, ".csv"), Story(2, ".csv"), Story(3, ".csv")}}}},
      {"axes",
       {{{"key", "montage.labelling.mu"}, {"log", {{"from", 10}, {"to", 1000}, {"count", 3}}}},
        {{"key", "montage.labelling.min_segment_length"}, {"values", {0, 60}}}}},
      {"metrics",
       {{{"name", "total_cost"}, {"file", "summary.json"}, {"key", "total_cost"}},
        {{"name", "segments"}, {"file", "summary.json"}, {"key", "segments"}}}}};
  return spec;
}

class SweepCliTest : public ::testing::Test {
 protected:
  fs::path WriteSpec(const json& spec, const std::string& name = "spec.json") {
    const fs::path path = temp_ / name;
    test_util::WriteText(path, spec.dump(2));
    return path;
  }
  // Every file of every cell's output except the provenance (run.json) and the timings inside
  // summary.json: the bytes a sweep must reproduce.
  static std::map<std::string, std::string> CellOutputs(const fs::path& dir) {
    std::map<std::string, std::string> files;
    for (const auto& entry : fs::recursive_directory_iterator(dir / "cells")) {
      if (!entry.is_regular_file()) continue;
      const std::string rel = fs::relative(entry.path(), dir).string();
      const std::string name = entry.path().filename().string();
      if (name == "run.json" || name == "provenance.json") continue;
      std::string bytes = ReadBytes(entry.path());
      if (name == "summary.json") {
        json j = json::parse(bytes);
        j.erase("seconds");
        bytes = j.dump();
      }
      files[rel] = bytes;
    }
    return files;
  }
  test_util::TempDir temp_;
};

TEST_F(SweepCliTest, DryRunPrintsTheCellsAndWritesThePlanOnly) {
  const fs::path spec = WriteSpec(ComposeSpec());
  const auto r = RunMmh("sweep --spec " + spec.string() + " --out " + (temp_ / "s").string() +
                        " --dry-run");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("6 cells (6 settings x 1 replicates)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("montage.labelling.mu=100.0"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(temp_ / "s" / "plan.json"));
  EXPECT_EQ(std::distance(fs::directory_iterator(temp_ / "s" / "configs"), fs::directory_iterator()),
            6);
  EXPECT_FALSE(fs::exists(temp_ / "s" / "cells"));
}

TEST_F(SweepCliTest, LocalSweepIsTheSameBytesWhateverTheJobsAndRerunsSkipCompleteCells) {
  json spec = ComposeSpec();
  const fs::path one = WriteSpec(spec, "one.json");
  const auto a = RunMmh("sweep --quiet --jobs 1 --spec " + one.string() + " --out " +
                        (temp_ / "a").string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_EQ(a.output, "");
  const std::string results = ReadBytes(temp_ / "a" / "results.csv");
  // Header, 6 rows; parameters as columns.
  EXPECT_EQ(std::count(results.begin(), results.end(), '\n'), 7) << results;
  EXPECT_EQ(results.substr(0, results.find('\n')),
            "cell,point,replicate,seed,montage.labelling.mu,montage.labelling.min_segment_length,"
            "total_cost,segments");
  EXPECT_EQ(ReadBytes(temp_ / "a" / "failures.csv"),
            "cell,point,replicate,seed,montage.labelling.mu,montage.labelling.min_segment_length,"
            "exit_code,signal,message\n");
  EXPECT_TRUE(fs::exists(temp_ / "a" / "plots" / "total_cost_heatmap.svg"));
  EXPECT_TRUE(fs::exists(temp_ / "a" / "plots" / "total_cost_vs_montage.labelling.mu.svg"));
  EXPECT_TRUE(fs::exists(temp_ / "a" / "plots" / "variance_shares.svg"));

  // The same cells through 3 jobs, one process per cell: the same bytes (the spec file differs
  // only in where it is; the cells' identities do not depend on it).
  spec["cells_per_worker"] = 1;
  const fs::path three = WriteSpec(spec, "three.json");
  const auto b = RunMmh("sweep --quiet --jobs 3 --spec " + three.string() + " --out " +
                        (temp_ / "b").string());
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_EQ(ReadBytes(temp_ / "b" / "results.csv"), results);
  EXPECT_EQ(ReadBytes(temp_ / "b" / "summary.csv"), ReadBytes(temp_ / "a" / "summary.csv"));
  EXPECT_EQ(CellOutputs(temp_ / "b"), CellOutputs(temp_ / "a"));

  // Against the command run by hand: a cell's output is what `mmh compose` writes.
  const json plan = json::parse(ReadBytes(temp_ / "a" / "plan.json"));
  const std::string id = plan["cells"][4]["id"];
  const auto direct = RunMmh("compose --quiet --takes " + Story(1, ".tum") + " " +
                             Story(2, ".tum") + " " + Story(3, ".tum") + " --annotations " +
                             Story(1, ".csv") + " " + Story(2, ".csv") + " " + Story(3, ".csv") +
                             " --config " + (temp_ / "a" / "configs" / (id + ".json")).string() +
                             " --out " + (temp_ / "direct").string());
  ASSERT_EQ(direct.exit_code, 0) << direct.output;
  EXPECT_EQ(ReadBytes(temp_ / "direct" / "montage.tum"),
            ReadBytes(temp_ / "a" / "cells" / id / "out" / "montage.tum"));

  // Running again continues: nothing to do, the same tables.
  const auto again = RunMmh("sweep --jobs 2 --spec " + one.string() + " --out " +
                            (temp_ / "a").string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("0 done now, 6 complete before, 0 failed"), std::string::npos)
      << again.output;
  EXPECT_EQ(ReadBytes(temp_ / "a" / "results.csv"), results);
  const auto status = RunMmh("sweep status " + (temp_ / "a").string());
  EXPECT_EQ(status.exit_code, 0);
  EXPECT_NE(status.output.find("6 cells: 6 done, 0 failed, 0 missing"), std::string::npos)
      << status.output;
}

TEST_F(SweepCliTest, BadInputIsExitTwoNamingSpecAxisAndValueAndWritesNothing) {
  json spec = ComposeSpec();
  spec["axes"][0]["key"] = "montage.labelling.mue";
  auto r = RunMmh("sweep --spec " + WriteSpec(spec).string() + " --out " + (temp_ / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("spec.json: axes[0] (montage.labelling.mue)"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("did you mean 'montage.labelling.mu'"), std::string::npos) << r.output;

  spec = ComposeSpec();
  spec["axes"][1]["values"] = {60, -5};
  r = RunMmh("sweep --spec " + WriteSpec(spec).string() + " --out " + (temp_ / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("axes[1] (montage.labelling.min_segment_length) value -5"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("an integer >= 0"), std::string::npos) << r.output;

  spec = ComposeSpec();
  spec["axes"][0]["key"] = "tracker.icp.iterations";
  r = RunMmh("sweep --spec " + WriteSpec(spec).string() + " --out " + (temp_ / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("not an option of `mmh compose`"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(temp_ / "o"));

  // An output folder of something else, then one of another spec.
  fs::create_directories(temp_ / "foreign");
  test_util::WriteText(temp_ / "foreign" / "notes.txt", "mine");
  const fs::path good = WriteSpec(ComposeSpec(), "good.json");
  r = RunMmh("sweep --dry-run --spec " + good.string() + " --out " + (temp_ / "foreign").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("a non-empty folder without plan.json"), std::string::npos) << r.output;
  // A sweep killed while writing its plan (configs/ before plan.json) is continued, its configs
  // written again; a configs/ folder holding anything else is still refused.
  fs::create_directories(temp_ / "killed" / "configs");
  test_util::WriteText(temp_ / "killed" / "configs" / "0123456789abcdef.json", "{\"cut");
  test_util::WriteText(temp_ / "killed" / "configs" / "x.json.tmp.99.0", "{");
  test_util::WriteText(temp_ / "killed" / "plan.json.tmp.99.1", "{");
  // A killed writer's (PID 2^22 + 1: above Linux's largest PID, so no process runs under it).
  test_util::WriteText(temp_ / "killed" / "configs" / "y.json.tmp.4194305.0", "{");
  r = RunMmh("sweep --dry-run --quiet --spec " + good.string() + " --out " +
             (temp_ / "killed").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(temp_ / "killed" / "plan.json"));
  EXPECT_FALSE(fs::exists(temp_ / "killed" / "configs" / "y.json.tmp.4194305.0"));
  for (const auto& e : fs::directory_iterator(temp_ / "killed" / "configs")) {
    const std::string name = e.path().filename().string();
    if (name.find(".tmp.") != std::string::npos || name == "0123456789abcdef.json") continue;
    EXPECT_NO_THROW(json::parse(ReadBytes(e.path()))) << name;
  }
  fs::create_directories(temp_ / "foreign" / "configs");
  test_util::WriteText(temp_ / "foreign" / "configs" / "notes.txt", "mine");
  fs::remove(temp_ / "foreign" / "notes.txt");
  r = RunMmh("sweep --dry-run --spec " + good.string() + " --out " + (temp_ / "foreign").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  ASSERT_EQ(RunMmh("sweep --dry-run --spec " + good.string() + " --out " +
                   (temp_ / "s").string()).exit_code, 0);
  spec = ComposeSpec();
  spec["axes"][1]["values"] = {0, 90};
  r = RunMmh("sweep --spec " + WriteSpec(spec, "changed.json").string() + " --out " +
             (temp_ / "s").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("keys that differ: axes.1.values.1"), std::string::npos) << r.output;

  // The Slurm backend with no sbatch on the PATH.
  fs::create_directories(temp_ / "empty_bin");
  r = RunMmh("sweep --backend slurm --spec " + good.string() + " --out " +
             (temp_ / "slurm").string() + " --slurm-bin " + (temp_ / "empty_bin").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("sbatch"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(temp_ / "slurm"));
}

TEST_F(SweepCliTest, FailedAndKilledCellsAreRecordedTheSweepGoesOnAndARerunFinishes) {
  json spec = ComposeSpec();
  spec["cells_per_worker"] = 3;  // a killed worker must cost only its running cell
  const fs::path file = WriteSpec(spec);
  const fs::path dir = temp_ / "f";
  ASSERT_EQ(RunMmh("sweep --dry-run --quiet --spec " + file.string() + " --out " + dir.string())
                .exit_code, 0);
  const json plan = json::parse(ReadBytes(dir / "plan.json"));
  const std::string failing = plan["cells"][1]["id"], killed = plan["cells"][3]["id"];
  const auto r = RunMmhWith("sweep --jobs 2 --spec " + file.string() + " --out " + dir.string(),
                            "MMH_SWEEP_FAULT=fail:" + failing + ",kill:" + killed);
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("4 done now, 0 complete before, 2 failed"), std::string::npos)
      << r.output;
  const std::string failures = ReadBytes(dir / "failures.csv");
  EXPECT_NE(failures.find(failing + ",1,0,"), std::string::npos) << failures;
  EXPECT_NE(failures.find("injected failure"), std::string::npos) << failures;
  EXPECT_NE(failures.find(killed + ",3,0,"), std::string::npos) << failures;
  EXPECT_NE(failures.find(",-1,9,"), std::string::npos) << failures;
  EXPECT_NE(failures.find("killed by signal 9"), std::string::npos) << failures;
  // No temporary left behind as a cell, every cell folder complete or failed.
  for (const auto& e : fs::directory_iterator(dir / "cells")) {
    EXPECT_TRUE(fs::exists(e.path() / "status.json")) << e.path();
  }
  const auto status = RunMmh("sweep status " + dir.string());
  EXPECT_NE(status.output.find("6 cells: 4 done, 2 failed, 0 missing"), std::string::npos)
      << status.output;

  const auto rerun = RunMmh("sweep --quiet --jobs 2 --spec " + file.string() + " --out " +
                            dir.string());
  EXPECT_EQ(rerun.exit_code, 0) << rerun.output;
  const auto clean = RunMmh("sweep --quiet --spec " + file.string() + " --out " +
                            (temp_ / "clean").string());
  ASSERT_EQ(clean.exit_code, 0) << clean.output;
  EXPECT_EQ(ReadBytes(dir / "results.csv"), ReadBytes(temp_ / "clean" / "results.csv"));
  EXPECT_EQ(CellOutputs(dir), CellOutputs(temp_ / "clean"));
}

TEST_F(SweepCliTest, ASweepKilledWithSigkillResumesWithoutLostOrDuplicatedCells) {
  json spec = ComposeSpec();
  spec["axes"][1]["values"] = {0, 30, 60};
  // The clean run for comparison packs its cells (same cells: packing is not part of a cell).
  const fs::path packed = WriteSpec(spec, "packed.json");
  spec["cells_per_worker"] = 1;
  const fs::path file = WriteSpec(spec);
  const fs::path dir = temp_ / "k";
  const std::string binary = MMH_BINARY;
  std::vector<std::string> args = {binary, "sweep", "--quiet", "--jobs", "1", "--spec",
                                   file.string(), "--out", dir.string()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, binary.c_str(), nullptr, nullptr, argv.data(), environ), 0);
  // Kill it once some cells are complete and others are not.
  const auto start = std::chrono::steady_clock::now();
  auto complete = [&] {
    int n = 0;
    std::error_code ec;
    for (fs::directory_iterator it(dir / "cells", ec), end; !ec && it != end; it.increment(ec)) {
      // A cell is complete under its final name: a temporary folder ('.'-prefixed) may already
      // hold its status.json when the kill comes before its rename, and is then redone.
      if (it->path().filename().string().front() == '.') continue;
      n += fs::exists(it->path() / "status.json");
    }
    return n;
  };
  while (complete() < 2 && std::chrono::steady_clock::now() - start < std::chrono::seconds(120)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(pid, SIGKILL);
  int wstatus = 0;
  waitpid(pid, &wstatus, 0);
  ASSERT_TRUE(WIFSIGNALED(wstatus));
  // The worker dies with the sweep (PR_SET_PDEATHSIG), but a rename already in the kernel when
  // the signal arrives still completes: count the complete cells once the worker is gone.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int before = complete();
  ASSERT_LT(before, 9) << "the sweep finished before it could be killed";
  const auto resumed = RunMmh("sweep --jobs 2 --spec " + file.string() + " --out " + dir.string());
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find(std::to_string(before) + " complete before"), std::string::npos)
      << resumed.output;
  int cells = 0;
  for (const auto& e : fs::directory_iterator(dir / "cells")) {
    ++cells;
    EXPECT_EQ(e.path().filename().string().front() != '.', true) << e.path();
  }
  EXPECT_EQ(cells, 9);
  ASSERT_EQ(RunMmh("sweep --quiet --spec " + packed.string() + " --out " +
                   (temp_ / "clean").string()).exit_code, 0);
  EXPECT_EQ(ReadBytes(dir / "results.csv"), ReadBytes(temp_ / "clean" / "results.csv"));
  EXPECT_EQ(CellOutputs(dir), CellOutputs(temp_ / "clean"));
}

// Every shipped spec plans (each axis and cell resolved by its command), and the metrics of the
// `run` specs name keys that mmh run's metrics.json has (the committed full-fidelity baseline
// run): a misspelt metric would otherwise show only after the whole sweep has run.
TEST_F(SweepCliTest, ShippedSpecsPlanAndTheirRunMetricsExist) {
  fs::current_path(MMH_SOURCE_DIR);  // the specs' paths are relative to the project
  const json metrics = json::parse(
      ReadBytes(fs::path(MMH_SOURCE_DIR) / "results" / "baseline" / "soldier" / "metrics.json"));
  int specs = 0, run_metrics = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(MMH_SOURCE_DIR) / "configs" / "sweeps")) {
    if (entry.path().extension() != ".json") continue;
    ++specs;
    const std::string name = entry.path().stem().string();
    const auto r = RunMmh("sweep --quiet --dry-run --spec " + entry.path().string() + " --out " +
                          (temp_ / name).string());
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.output;
    const json spec = json::parse(ReadBytes(entry.path()));
    if (spec["command"] != "run") continue;
    for (const json& m : spec["metrics"]) {
      ++run_metrics;
      EXPECT_EQ(m["file"], "metrics.json") << name;
      const json* value = sweep::FindKey(metrics, m["key"].get<std::string>());
      EXPECT_TRUE(value != nullptr && value->is_number()) << name << ": " << m["key"];
    }
  }
  EXPECT_GE(specs, 6);
  EXPECT_GE(run_metrics, 17);  // montage_quality's 9 and tracking_noise's 8
}

}  // namespace
}  // namespace mmh
