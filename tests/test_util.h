// Helpers shared by the test suites: a fresh temporary folder per use, and running the mmh binary
// as a user would.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "tests/statistical_frames.h"

#include "core/error.h"

namespace mmh::test_util {

// A new, empty folder under the system's temporary folder, named after the running test; removed
// (with anything a test made read-only in it) when the object goes.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("mmh_" + std::string(info ? info->test_suite_name() : "test") + "_" +
             std::string(info ? info->name() : "x") + "_" + std::to_string(::getpid()) + "_" +
             std::to_string(counter++) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all,
                                 std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

#ifdef MMH_TEST_DATA_DIR
// The committed real YCB-Video excerpt (tests/data/real/ycbv, PROVENANCE.md there) and its video
// 0000, which several suites track and score.
inline std::filesystem::path RealYcbvDir() {
  return std::filesystem::path(MMH_TEST_DATA_DIR) / "real" / "ycbv";
}
inline std::filesystem::path RealYcbvVideo() { return RealYcbvDir() / "data" / "0000"; }
#endif

// Writes `text` to `path` as it is (binary).
inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

// The whole file, byte for byte ("" when it cannot be read).
inline std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The names of the entries of `dir`, sorted.
inline std::vector<std::string> ListDir(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The message of the InputError `f` throws, or "(no InputError)".
inline std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// StatisticalFrameSettings as arguments of `mmh render` (and `run`): " --set '...'" each.
inline std::string StatisticalFramesFlags() {
  std::string flags;
  for (const std::string& s : StatisticalFrameSettings()) flags += " --set '" + s + "'";
  return flags;
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// Runs `mmh ARGUMENTS` (the binary under test, MMH_BINARY) through the shell.
inline CommandResult RunMmh(const std::string& arguments) {
  const std::string command = std::string(MMH_BINARY) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe)) result.output += buffer;
  result.exit_code = WEXITSTATUS(pclose(pipe));
  return result;
}

}  // namespace mmh::test_util
