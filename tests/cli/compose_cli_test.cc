// End-to-end tests of `mmh compose` as a user runs it: exit codes, messages naming the file,
// line, key and value, no output on bad input, identical bytes on a rerun.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <tuple>

#include "core/annotation.h"
#include "core/text_parsing.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;

using test_util::RunMmh;

class ComposeCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_);
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise(0.0, 0.002);
    for (int k = 0; k < 3; ++k) {
      const int frames = 200 + 20 * k;
      Trajectory take;
      Annotation annotation;
      for (int i = 0; i < frames; ++i) {
        const double u = static_cast<double>(i) / (frames - 1);  // story progress
        const double angle = 2 * M_PI * u;
        take.timestamps.push_back(i / 30.0);
        take.poses.emplace_back(
            Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())),
            Eigen::Vector3d(0.3 * std::cos(angle) + noise(rng), 0.3 * std::sin(angle) + noise(rng),
                            0.05));
        annotation.timestamps.push_back(i / 30.0);
        annotation.values.push_back(std::clamp(4.0 * std::sin(3 * angle + k), -5.0, 5.0));
      }
      WriteTum(dir_ / ("take_" + std::to_string(k) + ".tum"), take);
      WriteAnnotationCsv(dir_ / ("take_" + std::to_string(k) + ".csv"), annotation);
    }
  }
  std::string Inputs() const {
    std::string s = "--takes";
    for (int k = 0; k < 3; ++k) s += " " + (dir_ / ("take_" + std::to_string(k) + ".tum")).string();
    s += " --annotations";
    for (int k = 0; k < 3; ++k) s += " " + (dir_ / ("take_" + std::to_string(k) + ".csv")).string();
    return s;
  }

  test_util::TempDir temp_;
  const fs::path dir_ = temp_.path();
};

TEST_F(ComposeCliTest, WritesAllOutputsAndRerunGivesSameBytes) {
  const fs::path out1 = dir_ / "out1", out2 = dir_ / "out2";
  const auto r1 = RunMmh("compose " + Inputs() + " --out " + out1.string() + " --quiet");
  ASSERT_EQ(r1.exit_code, 0) << r1.output;
  const auto r2 =
      RunMmh("compose " + Inputs() + " --out " + out2.string() + " --threads 1 --quiet");
  ASSERT_EQ(r2.exit_code, 0) << r2.output;
  for (const char* name : {"montage.tum", "segments.csv", "timeline.csv", "config.resolved.json"}) {
    ASSERT_TRUE(fs::exists(out1 / name)) << name;
    EXPECT_EQ(ReadTextFile(out1 / name), ReadTextFile(out2 / name)) << name;
  }
  EXPECT_TRUE(fs::exists(out1 / "summary.json"));
  EXPECT_TRUE(fs::exists(out1 / "run.json"));
  const Trajectory montage = ReadTum(out1 / "montage.tum");
  EXPECT_GT(montage.size(), 150u);
  // The resolved config holds every default.
  const std::string resolved = ReadTextFile(out1 / "config.resolved.json");
  for (const char* key : {"\"mu\": 100.0", "\"min_segment_length\": 60", "\"lambda\": 2.5",
                          "\"lambda\": 0.8", "\"window\": 15", "\"reaction_time\": 0.3"}) {
    EXPECT_NE(resolved.find(key), std::string::npos) << key << "\n" << resolved;
  }
}

TEST_F(ComposeCliTest, SetOverridesReachTheResolvedConfig) {
  const fs::path out = dir_ / "out";
  const auto r = RunMmh("compose " + Inputs() + " --out " + out.string() +
                        " --quiet --set montage.labelling.min_segment_length=30"
                        " --set montage.blend.weight=smoothstep");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string resolved = ReadTextFile(out / "config.resolved.json");
  EXPECT_NE(resolved.find("\"min_segment_length\": 30"), std::string::npos);
  EXPECT_NE(resolved.find("\"weight\": \"smoothstep\""), std::string::npos);
}

TEST_F(ComposeCliTest, MarkersWriteTheMontagePosesAndKeepTheirSpacing) {
  const fs::path out = dir_ / "out";
  const auto r =
      RunMmh("compose " + Inputs() + " --out " + out.string() + " --quiet --markers 10 70");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Trajectory markers = ReadTum(out / "markers.tum");
  const Trajectory montage = ReadTum(out / "montage.tum");
  ASSERT_EQ(markers.size(), 2u);
  EXPECT_EQ(markers.timestamps[1], montage.timestamps[70]);
  EXPECT_EQ(markers.poses[1].translation, montage.poses[70].translation);
  const fs::path out2 = dir_ / "out2";
  const auto bad = RunMmh("compose " + Inputs() + " --out " + out2.string() + " --markers 10 69");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("frame 69"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("at least 60 frames"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(out2 / "montage.tum"));
}

struct BadCase {
  std::string name;
  std::string extra;                // appended arguments
  std::vector<std::string> expect;  // substrings of the message
};

TEST_F(ComposeCliTest, BadInputExitsTwoNamesTheProblemAndWritesNothing) {
  // Files with defects.
  std::ofstream(dir_ / "nan.tum") << "0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n";
  std::ofstream(dir_ / "zero_q.tum") << "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 0\n";
  std::ofstream(dir_ / "empty.tum") << "# nothing\n";
  std::ofstream(dir_ / "config.json") << "{\"montage\": {\"labelling\": {\"mu\": 100, \"dd\": 3}}}";
  std::ofstream(dir_ / "broken.json") << "{\"montage\": {\n  \"mu\": ,\n}}";
  const std::string t0 = (dir_ / "take_0.tum").string();
  const std::string a0 = (dir_ / "take_0.csv").string();
  const std::string a1 = (dir_ / "take_1.csv").string();
  const std::vector<BadCase> cases = {
      {"misspelt key",
       Inputs() + " --set montage.labelling.mu_=3",
       {"montage.labelling.mu_", "unknown", "did you mean 'mu'"}},
      {"wrong type",
       Inputs() + " --set montage.dtw.lambda=\\\"x\\\"",
       {"montage.dtw.lambda", "\"x\"", "a number"}},
      {"out of range",
       Inputs() + " --set montage.blend.window=14",
       {"montage.blend.window", "14", "odd"}},
      {"unknown enum",
       Inputs() + " --set montage.dtw.step_pattern=diagonal",
       {"montage.dtw.step_pattern", "diagonal", "literal"}},
      {"unknown key in file",
       Inputs() + " --config " + (dir_ / "config.json").string(),
       {"config.json", "montage.labelling.dd", "unknown"}},
      {"invalid json",
       Inputs() + " --config " + (dir_ / "broken.json").string(),
       {"broken.json:2:"}},
      {"one take", "--takes " + t0 + " --annotations " + a0, {"at least 2 takes"}},
      {"annotation count",
       "--takes " + t0 + " " + t0 + " --annotations " + a0,
       {"--annotations", "1 files for 2 takes"}},
      {"length mismatch",
       "--takes " + t0 + " " + t0 + " --annotations " + a0 + " " + a1,
       {"take_1.csv", "220 rows", "200 rows"}},
      {"nan pose",
       "--takes " + t0 + " " + (dir_ / "nan.tum").string() + " --annotations " + a0 + " " + a0,
       {"nan.tum:2", "tx", "'nan'"}},
      {"zero quaternion",
       "--takes " + t0 + " " + (dir_ / "zero_q.tum").string() + " --annotations " + a0 + " " + a0,
       {"zero_q.tum:2", "zero quaternion"}},
      {"empty file",
       "--takes " + t0 + " " + (dir_ / "empty.tum").string() + " --annotations " + a0 + " " + a0,
       {"empty.tum", "no poses"}},
      {"missing file",
       "--takes " + t0 + " /nonexistent/x.tum --annotations " + a0 + " " + a0,
       {"/nonexistent/x.tum", "does not exist"}},
      {"take shorter than d",
       Inputs() + " --set montage.labelling.min_segment_length=250",
       {"take_0.tum", "200 frames", "more than montage.labelling.min_segment_length = 250"}},
      {"unknown flag", Inputs() + " --bogus", {"bogus"}},
  };
  for (const auto& c : cases) {
    const fs::path out = dir_ / ("out_" + std::to_string(&c - cases.data()));
    const auto r = RunMmh("compose " + c.extra + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << c.name << "\n" << r.output;
    for (const auto& e : c.expect) {
      EXPECT_NE(r.output.find(e), std::string::npos) << c.name << ": '" << e << "' not in\n"
                                                     << r.output;
    }
    EXPECT_FALSE(fs::exists(out / "montage.tum")) << c.name;
  }
}

TEST_F(ComposeCliTest, UnwritableOutputIsAnInputError) {
  std::ofstream(dir_ / "file") << "x";
  const auto r = RunMmh("compose " + Inputs() + " --out " + (dir_ / "file" / "sub").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("file/sub"), std::string::npos) << r.output;
}

// Takes at 1e150..1e300 m crashed the DTW (SIGSEGV, or a heap write in the symmetric pattern):
// refused where they are read, naming the file, line and field.
TEST_F(ComposeCliTest, HugeTranslationsAreRefusedWhereRead) {
  for (const char* value : {"1e150", "1e200", "1e300", "1000001"}) {
    std::ofstream huge(dir_ / "huge.tum");
    for (int i = 0; i < 200; ++i) {
      huge << i / 30.0 << " " << value << " " << value << " " << value << " 0 0 0 1\n";
    }
    huge.close();
    for (const char* pattern : {"literal", "symmetric", "slope_limited"}) {
      const fs::path out = dir_ / "out";
      const auto r = RunMmh("compose --takes " + (dir_ / "take_0.tum").string() + " " +
                            (dir_ / "huge.tum").string() + " --annotations " +
                            (dir_ / "take_0.csv").string() + " " + (dir_ / "take_0.csv").string() +
                            " --set montage.dtw.step_pattern=" + pattern +
                            " --set montage.dtw.prune=false --out " + out.string());
      EXPECT_EQ(r.exit_code, 2) << value << " " << pattern << "\n" << r.output;
      EXPECT_NE(r.output.find("huge.tum:1, field tx: got '" + std::string(value) + "'"),
                std::string::npos)
          << r.output;
      EXPECT_NE(r.output.find("within +-1e6 m"), std::string::npos) << r.output;
      EXPECT_FALSE(fs::exists(out));
    }
  }
}

TEST_F(ComposeCliTest, AnnotationTimestampsMustBeTheTakes) {
  const Annotation a = ReadAnnotationCsv(dir_ / "take_1.csv");
  for (const auto& [name, scale, shift] :
       {std::tuple{"milliseconds", 1000.0, 0.0}, std::tuple{"shifted", 1.0, 1000.0}}) {
    Annotation bad = a;
    for (double& t : bad.timestamps) t = t * scale + shift;
    WriteAnnotationCsv(dir_ / "bad.csv", bad);
    const fs::path out = dir_ / "out";
    const auto r =
        RunMmh("compose --takes " + (dir_ / "take_0.tum").string() + " " +
               (dir_ / "take_1.tum").string() + " --annotations " + (dir_ / "take_0.csv").string() +
               " " + (dir_ / "bad.csv").string() + " --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << name << "\n" << r.output;
    EXPECT_NE(r.output.find("bad.csv, row "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("expected the timestamp of frame"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("take_1.tum"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }
}

// summary.json is a function of the inputs (timings are in run.json only), and the folder is
// written whole: a rerun replaces it, a folder mmh did not write is never touched, and the staging
// folder of a killed run is removed by the next.
TEST_F(ComposeCliTest, OutputFolderIsWholeDeterministicAndReplaceable) {
  const fs::path out = dir_ / "out";
  ASSERT_EQ(RunMmh("compose " + Inputs() + " --out " + out.string() + " --quiet").exit_code, 0);
  const std::string summary = ReadTextFile(out / "summary.json");
  EXPECT_EQ(summary.find("\"seconds\""), std::string::npos) << summary;
  EXPECT_NE(ReadTextFile(out / "run.json").find("\"seconds\""), std::string::npos);
  // A killed run's staging folder (a process id that no longer runs).
  const pid_t child = fork();
  if (child == 0) _exit(0);
  waitpid(child, nullptr, 0);
  const fs::path stale = dir_ / ("out.partial-" + std::to_string(child));
  fs::create_directories(stale);
  std::ofstream(stale / "montage.tum") << "half";
  const auto rerun = RunMmh("compose " + Inputs() + " --out " + out.string() + " --quiet");
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  EXPECT_EQ(ReadTextFile(out / "summary.json"), summary);
  EXPECT_FALSE(fs::exists(stale));
  // Nothing beside the folder but the inputs.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find("out."), std::string::npos) << entry.path();
  }
  // A folder of someone else's files is refused and left as it is.
  const fs::path theirs = dir_ / "theirs";
  fs::create_directories(theirs);
  std::ofstream(theirs / "notes.txt") << "mine";
  const auto refused = RunMmh("compose " + Inputs() + " --out " + theirs.string());
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("an existing folder that mmh did not write"), std::string::npos)
      << refused.output;
  EXPECT_EQ(ReadTextFile(theirs / "notes.txt"), "mine");
  EXPECT_FALSE(fs::exists(theirs / "montage.tum"));
}

}  // namespace
}  // namespace mmh
