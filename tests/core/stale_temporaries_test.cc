// Tests of core/stale_temporaries.h: only the temporaries of writers that no longer run go.
#include "core/stale_temporaries.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::ListDir;
using test_util::TempDir;

// The PID of a process that has exited and been reaped (none runs under it until the kernel
// reuses it, much later).
long DeadPid() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);
  return child;
}

TEST(StaleTemporaries, OnlyTheTemporariesOfExitedWritersAreRemoved) {
  TempDir dir;
  const std::string dead = std::to_string(DeadPid());
  const std::string alive = std::to_string(::getpid());
  EnsureDirectory(dir / "takes" / "take_0");
  for (const fs::path& file :
       {dir / "metrics.json", dir / ("metrics.json.tmp." + dead + ".3"),
        dir / "takes" / "take_0" / ("tracked.tum.tmp." + dead + ".0"),
        dir / "takes" / "take_0" / ("depth.tmp." + dead + ".12.png"),  // the image writer's
        dir / ("config.json.tmp." + alive + ".1"),                      // a running writer's
        dir / "notes.tmp.txt", dir / ("x.tmp." + dead),                 // not a temporary's name
        dir / ("x.tmp." + dead + ".1.two.dots")}) {
    WriteFileAtomically(file, std::string("x"));
  }
  EXPECT_EQ(RemoveStaleTemporaries(dir.path(), /*subfolders=*/false), 1);  // metrics.json's
  EXPECT_EQ(ListDir(dir / "takes" / "take_0").size(), 2u);
  EXPECT_EQ(RemoveStaleTemporaries(dir.path()), 2);
  EXPECT_EQ(ListDir(dir.path()),
            (std::vector<std::string>{"config.json.tmp." + alive + ".1", "metrics.json",
                                      "notes.tmp.txt", "takes", "x.tmp." + dead,
                                      "x.tmp." + dead + ".1.two.dots"}));
  EXPECT_TRUE(ListDir(dir / "takes" / "take_0").empty());
  EXPECT_EQ(RemoveStaleTemporaries(dir / "missing"), 0);
}

}  // namespace
}  // namespace mmh
