// The committed golden values are what R computes: make_golden.R, run live when Rscript is
// installed, reproduces golden.json.
#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/stats/golden.h"
#include "tests/test_util.h"

namespace mmh::study {
namespace {

// Same shape; numbers equal to 1e-9 relative (another BLAS may round lme4's algebra differently).
void ExpectSameJson(const nlohmann::json& a, const nlohmann::json& b, const std::string& path) {
  if (a.is_number() && b.is_number()) {
    EXPECT_TRUE(stats::golden::Near(a.get<double>(), b.get<double>(), 1e-9)) << path;
    return;
  }
  ASSERT_EQ(a.type(), b.type()) << path;
  if (a.is_object()) {
    ASSERT_EQ(a.size(), b.size()) << path;
    for (auto it = a.begin(); it != a.end(); ++it) {
      ASSERT_TRUE(b.contains(it.key())) << path << "." << it.key();
      if (it.key() == "r_version" || it.key() == "lme4_version" || it.key() == "lmerTest_version") {
        continue;
      }
      ExpectSameJson(it.value(), b[it.key()], path + "." + it.key());
    }
  } else if (a.is_array()) {
    ASSERT_EQ(a.size(), b.size()) << path;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ExpectSameJson(a[i], b[i], path + "[" + std::to_string(i) + "]");
    }
  } else {
    EXPECT_EQ(a, b) << path;
  }
}

TEST(GoldenValues, MakeGoldenRReproducesTheCommittedFile) {
  if (std::system("command -v Rscript >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "Rscript not installed";
  }
  test_util::TempDir dir;
  const std::string script =
      (std::filesystem::path(MMH_TEST_DATA_DIR) / "study" / "make_golden.R").string();
  const std::string command = "Rscript '" + script + "' '" + (dir / "golden.json").string() +
                              "' >'" + (dir / "log").string() + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << test_util::ReadBytes(dir / "log");
  ExpectSameJson(stats::golden::ReadJsonFile(dir / "golden.json"), stats::golden::Golden(),
                 "golden");
}

}  // namespace
}  // namespace mmh::study
