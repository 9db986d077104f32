// A sweep through a REAL single-node Slurm cluster started for the test
// (tests/sweep/with_slurm_cluster.sh: munged, slurmctld -D, slurmd -D; every daemon stopped when
// it ends) running tests/sweep/slurm_sweep_scenario.sh: submission, a requeued task, a failed
// cell, resubmission of the missing one, aggregation after the arrays, and the aggregated tables
// equal to the local backend's. Skipped (with the reason) when not root or Slurm is not installed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "tests/test_util.h"

namespace mmh {
namespace {

TEST(SlurmClusterTest, SweepThroughARealClusterEqualsTheLocalBackend) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to start munged, slurmctld and slurmd";
  for (const char* tool : {"/usr/sbin/munged", "/usr/sbin/slurmctld", "/usr/sbin/slurmd"}) {
    if (access(tool, X_OK) != 0) {
      GTEST_SKIP() << tool << " is not installed (./mmh installs munge, slurmctld, slurmd)";
    }
  }
  test_util::TempDir work;
  const std::string tests = std::string(MMH_SOURCE_DIR) + "/tests/sweep/";
  const std::string command = "MMH_SLURM_MAX_ARRAY_SIZE=4 " + tests + "with_slurm_cluster.sh " +
                              tests + "slurm_sweep_scenario.sh " + MMH_BINARY + " " +
                              MMH_SOURCE_DIR + " " + work.path().string() + " 2>&1";
  std::string output;
  FILE* pipe = popen(command.c_str(), "r");
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe)) output += buffer;
  const int status = pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << output;
  EXPECT_EQ(WEXITSTATUS(status), 0) << output;
  EXPECT_NE(output.find("slurm sweep scenario: ok"), std::string::npos) << output;
}

}  // namespace
}  // namespace mmh
