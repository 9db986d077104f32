// The two executables (cli/full_executable.h, docs/architecture.md "Start-up"): the light `mmh`
// loads none of the heavy libraries, and hands every other command to `mmh-full` with the same
// help, errors and exit codes.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::RunMmh;

const fs::path kFull = fs::path(MMH_BINARY).parent_path() / "mmh-full";

// Runs a shell command; stdout and stderr.
test_util::CommandResult Shell(const std::string& command) {
  test_util::CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  result.exit_code = WEXITSTATUS(pclose(pipe));
  return result;
}

// The shared objects the dynamic loader maps for `binary` (its ldd mode), one per line.
std::string LoadedLibraries(const fs::path& binary) {
  return Shell("LD_TRACE_LOADED_OBJECTS=1 " + binary.string()).output;
}

// `output` with every mention of mmh-full's path replaced by mmh's, as if mmh had printed it.
std::string AsMmh(std::string output) {
  for (std::size_t at; (at = output.find(kFull.string())) != std::string::npos;) {
    output.replace(at, kFull.string().size(), MMH_BINARY);
  }
  return output;
}

TEST(StartupTest, LightExecutableLoadsNoHeavyLibrary) {
  const std::string light = LoadedLibraries(MMH_BINARY);
  const std::string full = LoadedLibraries(kFull);
  // The check itself sees them: mmh-full loads the tracker's and the renderer's.
  for (const char* heavy : {"libpcl_", "libopencv_", "libembree"}) {
    EXPECT_EQ(light.find(heavy), std::string::npos) << heavy << " in:\n" << light;
    EXPECT_NE(full.find(heavy), std::string::npos) << heavy << " not in mmh-full";
  }
  // OpenImageIO is a plugin of both, loaded when an image is read; assimp is linked by neither
  // (mmh reads meshes itself).
  for (const char* plugin_library : {"libOpenImageIO", "libassimp"}) {
    EXPECT_EQ(light.find(plugin_library), std::string::npos) << light;
    EXPECT_EQ(full.find(plugin_library), std::string::npos) << full;
  }
  // vdso, loader, libc, libm, libgcc_s, libstdc++, TBB; a sanitized build's runtimes
  // (libasan, libubsan: `./mmh test --sanitize`) are not the program's and are not counted.
  int lines = 0;
  std::istringstream listing(light);
  for (std::string line; std::getline(listing, line);) {
    lines += line.find("libasan") == std::string::npos && line.find("libubsan") == std::string::npos;
  }
  EXPECT_LE(lines, 8) << light;
  const auto version = RunMmh("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.output, Shell(kFull.string() + " --version").output);
  EXPECT_FALSE(version.output.empty());
}

TEST(StartupTest, OtherCommandsRunInMmhFullWithTheSameHelpErrorsAndExitCodes) {
  // mmh-full starts in 0.2-1 s: few cases.
  for (const std::string args : {"--help", "run --help", "", "bogus", "study --bogus",
                                 "compose --help"}) {
    const auto via_mmh = RunMmh(args);
    const auto full = Shell(kFull.string() + " " + args);
    EXPECT_EQ(via_mmh.exit_code, full.exit_code) << args;
    EXPECT_EQ(via_mmh.output, AsMmh(full.output)) << args;
  }
  const auto help = RunMmh("--help");
  EXPECT_NE(help.output.find("render"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("sweep"), std::string::npos) << help.output;
  EXPECT_EQ(RunMmh("bogus").exit_code, 2);
}

// Every file of folder `a` (recursively) but the provenance and timings equals `b`'s.
void ExpectSameResults(const fs::path& a, const fs::path& b) {
  std::size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), a);
    if (relative == "run.json" || relative == "timings.csv") continue;
    ++files;
    EXPECT_EQ(test_util::ReadBytes(entry.path()), test_util::ReadBytes(b / relative)) << relative;
  }
  EXPECT_GT(files, 5u) << a;
}

// The light mmh runs `run` and `study` in fast fidelity itself (no renderer, no tracker: the
// error model on the ground truth), with the same bytes as mmh-full; full fidelity goes to
// mmh-full. A copy of mmh without mmh-full beside it tells which program ran.
TEST(StartupTest, FastRunsStudiesAndTheirSweepsRunInTheLightExecutable) {
  // The configs' paths are relative to the project (as when run from it).
  fs::current_path(MMH_SOURCE_DIR);
  test_util::TempDir dir;
  const fs::path alone = dir.path() / "mmh";
  fs::copy_file(MMH_BINARY, alone);
  const std::string fast = " --set 'run.fidelity=\"fast\"' --quiet --threads 1 --out ";
  const std::string run = " run --config configs/soldier.json" + fast;
  const auto light_run = Shell(alone.string() + run + (dir.path() / "run_light").string());
  ASSERT_EQ(light_run.exit_code, 0) << light_run.output;
  ASSERT_EQ(Shell(kFull.string() + run + (dir.path() / "run_full").string()).exit_code, 0);
  ExpectSameResults(dir.path() / "run_light", dir.path() / "run_full");

  const std::string study =
      " study --config configs/study_soldier.json --set study.animators=6 --replicates 2" + fast;
  const auto light_study = Shell(alone.string() + study + (dir.path() / "study_light").string());
  ASSERT_EQ(light_study.exit_code, 0) << light_study.output;
  ASSERT_EQ(Shell(kFull.string() + study + (dir.path() / "study_full").string()).exit_code, 0);
  ExpectSameResults(dir.path() / "study_light", dir.path() / "study_full");

  // A sweep of fast run cells: planned and its first cell run by the light worker.
  const fs::path sweep = dir.path() / "sweep_fast";
  const auto plan = Shell(alone.string() + " sweep --spec configs/sweeps/montage_quality.json" +
                          " --dry-run --quiet --out " + sweep.string());
  ASSERT_EQ(plan.exit_code, 0) << plan.output;
  const auto worker = Shell(alone.string() + " sweep worker " + sweep.string() + " --cells 0");
  EXPECT_EQ(worker.exit_code, 0) << worker.output;
  const auto status = Shell(alone.string() + " sweep status " + sweep.string());
  EXPECT_NE(status.output.find("1 done, 0 failed"), std::string::npos) << status.output;

  // Full fidelity (the configs' default) needs mmh-full: a run, a study and a sweep of full-
  // fidelity run cells each say that they cannot start it, and write nothing.
  const std::string missing = "cannot start " + (dir.path() / "mmh-full").string();
  for (const std::string& args :
       {"run --config configs/soldier.json --quiet --out " + (dir.path() / "run_ff").string(),
        "study --config configs/study_soldier.json --quiet --out " +
            (dir.path() / "study_ff").string(),
        "sweep --spec configs/sweeps/tracking_noise.json --quiet --out " +
            (dir.path() / "sweep_ff").string()}) {
    const auto r = Shell(alone.string() + " " + args);
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_NE(r.output.find(missing), std::string::npos) << args << ": " << r.output;
  }
  EXPECT_FALSE(fs::exists(dir.path() / "run_ff"));
  EXPECT_FALSE(fs::exists(dir.path() / "study_ff"));
  EXPECT_FALSE(fs::exists(dir.path() / "sweep_ff" / "cells"));
}

TEST(StartupTest, SweepsOfTrackArePlannedByMmhFull) {
  fs::current_path(MMH_SOURCE_DIR);
  test_util::TempDir dir;
  const fs::path alone = dir.path() / "mmh";
  fs::copy_file(MMH_BINARY, alone);
  test_util::WriteText(dir.path() / "track.json",
                       R"({"command": "track", "inputs": {"input": "examples/synthetic_story"},
                          "axes": [{"key": "tracker.icp.iterations", "values": [10, 20]}],
                          "metrics": [{"name": "m", "file": "metrics.json", "key": "m"}]})");
  const auto r = Shell(alone.string() + " sweep --spec " + (dir.path() / "track.json").string() +
                       " --dry-run --quiet --out " + (dir.path() / "s").string());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("cannot start " + (dir.path() / "mmh-full").string()), std::string::npos)
      << r.output;
}

TEST(StartupTest, WithoutMmhFullTheLightCommandsStillRunAndTheOthersFailClearly) {
  test_util::TempDir dir;
  const fs::path alone = dir.path() / "mmh";
  fs::copy_file(MMH_BINARY, alone);
  const auto version = Shell(alone.string() + " --version");
  EXPECT_EQ(version.exit_code, 0) << version.output;
  const auto help = Shell(alone.string() + " compose --help");
  EXPECT_EQ(help.exit_code, 0) << help.output;
  const auto render = Shell(alone.string() + " render --help");
  EXPECT_EQ(render.exit_code, 1);
  EXPECT_NE(render.output.find("cannot start " + (dir.path() / "mmh-full").string()),
            std::string::npos)
      << render.output;
}

// An installed or moved tree (PREFIX/bin/mmh, mmh-full; PREFIX/lib/mmh/ the plugins, as
// `cmake --install` lays it out) loads its own plugins, found from the executable's folder: with
// the plugin removed from the copy, the build tree's (still in place) is not used instead.
TEST(StartupTest, AMovedTreeLoadsThePluginsBesideItsExecutables) {
  test_util::TempDir dir;
  const fs::path prefix = dir.path() / "moved";
  fs::create_directories(prefix / "bin");
  fs::create_directories(prefix / "lib" / "mmh");
  fs::copy_file(MMH_BINARY, prefix / "bin" / "mmh");
  fs::copy_file(kFull, prefix / "bin" / "mmh-full");
  const fs::path plugin = fs::path(MMH_BINARY).parent_path() / ".." / "lib" / "mmh" /
                          "libmmh_oiio_image_io.so";
  ASSERT_TRUE(fs::exists(plugin)) << plugin;
  fs::copy_file(plugin, prefix / "lib" / "mmh" / "libmmh_oiio_image_io.so");
  // A render writes PNGs (OpenImageIO, through the plugin); it runs in the copy's mmh-full.
  const std::string render = "env -u MMH_PLUGIN_DIR " + (prefix / "bin" / "mmh").string() +
                             " render --quiet --set render.frames=2 --out ";
  const auto moved = Shell(render + (dir.path() / "a").string());
  ASSERT_EQ(moved.exit_code, 0) << moved.output;
  ASSERT_TRUE(fs::exists(dir.path() / "a" / "depth"));
  EXPECT_EQ(test_util::ListDir(dir.path() / "a" / "depth").size(), 2u);

  fs::remove(prefix / "lib" / "mmh" / "libmmh_oiio_image_io.so");
  const auto missing = Shell(render + (dir.path() / "b").string());
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("cannot load the plugin " +
                                (prefix / "lib" / "mmh" / "libmmh_oiio_image_io.so").string()),
            std::string::npos)
      << missing.output;
  EXPECT_FALSE(fs::exists(dir.path() / "b" / "depth"));

  // MMH_PLUGIN_DIR names another folder.
  const auto overridden =
      Shell("MMH_PLUGIN_DIR=" + plugin.parent_path().string() + " " +
            (prefix / "bin" / "mmh").string() + " render --quiet --set render.frames=2 --out " +
            (dir.path() / "c").string());
  EXPECT_EQ(overridden.exit_code, 0) << overridden.output;
}

}  // namespace
}  // namespace mmh
