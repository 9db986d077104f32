// Tests of core/temporary_name.h: the writers' temporaries and the owner read back from the name.
#include "core/temporary_name.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

namespace mmh {
namespace {

TEST(TemporaryName, NamesAreUniqueAndTheirOwnerReadsBack) {
  const std::string pid = std::to_string(::getpid());
  const auto a = TemporaryBeside("out/metrics.json");
  const auto b = TemporaryBeside("out/metrics.json");
  EXPECT_NE(a, b);
  EXPECT_EQ(a.parent_path(), "out");
  EXPECT_EQ(a.filename().string().rfind("metrics.json.tmp." + pid + ".", 0), 0u) << a;
  const auto image = TemporaryBeside("out/depth/000001.png", /*keep_extension=*/true);
  EXPECT_EQ(image.extension(), ".png");
  EXPECT_EQ(image.filename().string().rfind("000001.tmp." + pid + ".", 0), 0u) << image;
  for (const auto& name : {a, b, image}) {
    EXPECT_EQ(TemporaryOwner(name.filename().string()), ::getpid()) << name;
  }
  for (const char* other : {"metrics.json", "notes.tmp.txt", "x.tmp.12", "x.tmp.12.1.two.dots",
                            ".tmp.12.1", "x.tmp.1234567890.1"}) {
    EXPECT_EQ(TemporaryOwner(other), -1) << other;
  }
}

}  // namespace
}  // namespace mmh
