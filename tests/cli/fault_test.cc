// Faults: `render`, `run`, `study` and `sweep` killed with SIGKILL at several moments never leave
// a partial file under a final name, and a rerun (or `run --resume`) completes with the same bytes
// as an uninterrupted run. (The thread count and reruns of every subcommand: determinism_test.cc.)
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::ReadBytes;
using test_util::RunMmh;
using test_util::TempDir;

// Every file under `dir` by relative path -> bytes, but those that hold timings or provenance.
std::map<std::string, std::string> Contents(const fs::path& dir,
                                            const std::set<std::string>& skip) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const std::string name = fs::relative(e.path(), dir).string();
    if (skip.count(e.path().filename().string())) continue;
    files[name] = ReadBytes(e.path());
  }
  return files;
}

// Starts `mmh ARGS` (split on spaces), kills it with SIGKILL after `delay`, reaps it. Returns
// false when it had already finished.
bool KillAfter(const std::vector<std::string>& args, std::chrono::milliseconds delay) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    static std::string binary = MMH_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  std::this_thread::sleep_for(delay);
  int status = 0;
  const bool running = waitpid(pid, &status, WNOHANG) == 0;
  if (running) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  return running;
}

std::vector<std::string> Split(const std::string& text) {
  std::vector<std::string> parts;
  std::istringstream in(text);
  for (std::string p; in >> p;) parts.push_back(p);
  return parts;
}

// No temporary or staging file may be left under a final name; staging leftovers (named
// '.partial-PID' or '.tmp.PID.N') are allowed only until the next run.
void ExpectOnlyCompleteOrAbsent(const fs::path& out, const std::map<std::string, std::string>& ref,
                                const std::set<std::string>& skip) {
  if (!fs::exists(out)) return;
  for (const auto& [name, bytes] : Contents(out, skip)) {
    if (name.find(".tmp.") != std::string::npos) continue;  // a temporary, never a final name
    const auto it = ref.find(name);
    ASSERT_NE(it, ref.end()) << "unexpected file " << name;
    EXPECT_EQ(bytes, it->second) << "partial or different file under a final name: " << name;
  }
}

struct Scenario {
  std::string name;
  std::string args;               // without --out
  std::string rerun_flags;        // e.g. --resume, when the killed run wrote its config
  std::set<std::string> timings;  // files that hold timings (compared by existence only)
  // When to kill, as fractions of the uninterrupted run's wall time (a fixed delay in ms
  // missed every run of a 0.2 s sweep on a faster machine); above 1, after it should have ended.
  std::vector<double> kill_at;
  bool whole_folder = true;  // the folder appears complete or not at all
};

// Runs from the source tree (the shipped configs name their stories relative to it).
class FaultTest : public ::testing::Test {
 protected:
  void SetUp() override {
    previous_ = fs::current_path();
    fs::current_path(MMH_SOURCE_DIR);
  }
  void TearDown() override { fs::current_path(previous_); }
  fs::path previous_;
};

void KillAndRerun(const Scenario& s) {
  TempDir dir;
  const fs::path ref = dir / "ref";
  const auto start = std::chrono::steady_clock::now();
  const auto r = RunMmh(s.args + " --quiet --out " + ref.string());
  const double ref_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto expected = Contents(ref, s.timings);
  ASSERT_FALSE(expected.empty());
  int killed = 0;
  for (size_t i = 0; i < s.kill_at.size(); ++i) {
    const int ms = std::max(5, static_cast<int>(s.kill_at[i] * ref_ms));
    SCOPED_TRACE(s.name + " killed after " + std::to_string(ms) + " ms");
    const fs::path out = dir / ("out_" + std::to_string(i));
    killed +=
        KillAfter(Split(s.args + " --quiet --out " + out.string()), std::chrono::milliseconds(ms));
    if (s.whole_folder && fs::exists(out)) {
      // Complete or absent: when it is there, everything is.
      EXPECT_EQ(Contents(out, s.timings), expected);
    } else {
      ExpectOnlyCompleteOrAbsent(out, expected, s.timings);
    }
    // --resume continues a run that got as far as its resolved config; before that, a rerun.
    const std::string flags = fs::exists(out / "config.resolved.json") ? s.rerun_flags : "";
    const auto again = RunMmh(s.args + " " + flags + " --quiet --out " + out.string());
    ASSERT_EQ(again.exit_code, 0) << again.output;
    EXPECT_EQ(Contents(out, s.timings), expected);
    for (const auto& e : fs::directory_iterator(dir.path())) {
      EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos)
          << "staging folder left after the rerun: " << e.path();
    }
  }
  // At least one kill must have hit a running process, or the test proves nothing.
  EXPECT_GE(killed, 1) << "every run finished before its kill: raise the work";
}

TEST_F(FaultTest, RenderKilledLeavesNothingPartialAndARerunGivesTheSameBytes) {
  KillAndRerun({"render",
                "render --set render.frames=45 --threads 2",
                "",
                {"run.json", "render_summary.json"},
                {0.015, 0.15, 0.45, 1.0}});
}

// The last kill may come after the run finished: `--resume` of a complete folder must give the
// same bytes too (metrics.json used to count the frames rendered by this process, 0 on resume).
TEST_F(FaultTest, RunKilledResumesToTheSameBytes) {
  KillAndRerun({"run",
                "run --config " + std::string(MMH_SOURCE_DIR) +
                    "/configs/soldier.json --set render.frames=70 --threads 2",
                "--resume",
                {"run.json", "timings.csv"},
                {0.13, 1.0, 2.6},
                /*whole_folder=*/false});
}

TEST_F(FaultTest, StudyKilledLeavesNothingPartialAndARerunGivesTheSameBytes) {
  KillAndRerun({"study",
                "study --config " + std::string(MMH_SOURCE_DIR) +
                    "/configs/study_soldier.json --set run.fidelity=fast --set study.animators=6 "
                    "--threads 2",
                "",
                {"run.json"},
                {0.15, 0.6, 1.8}});
}

// A sweep continues when run again (cells whose status says done are skipped): killed while its
// cells run, a rerun completes to the bytes of an uninterrupted sweep.
TEST_F(FaultTest, SweepKilledContinuesToTheSameBytes) {
  TempDir spec_dir;
  const std::string story = std::string(MMH_SOURCE_DIR) + "/examples/synthetic_story/take_";
  std::string takes, annotations;
  for (int k = 1; k <= 3; ++k) {
    takes += std::string(k > 1 ? ", " : "") + "\"" + story + std::to_string(k) + ".tum\"";
    annotations += std::string(k > 1 ? ", " : "") + "\"" + story + std::to_string(k) + ".csv\"";
  }
  // 9 compose cells.
  const fs::path spec = spec_dir / "spec.json";
  test_util::WriteText(spec, R"({"command": "compose", "inputs": {"takes": [)" + takes +
                                 R"(], "annotations": [)" + annotations + R"(]},
    "axes": [{"key": "montage.labelling.mu", "values": [10, 100, 1000]},
             {"key": "montage.labelling.min_segment_length", "values": [0, 30, 60]}],
    "metrics": [{"name": "total_cost", "file": "summary.json", "key": "total_cost"}]})");
  KillAndRerun({"sweep",
                "sweep --jobs 2 --threads 2 --spec " + spec.string(),
                "",
                {"run.json", "provenance.json"},
                {0.1, 0.4, 0.75},
                /*whole_folder=*/false});
}

}  // namespace
}  // namespace mmh
