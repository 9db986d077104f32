// Tests of core/resource_limits.h: absurd requests are refused with a short, clear message.
#include "core/resource_limits.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace mmh {
namespace {

using test_util::ErrorOf;
using ::testing::HasSubstr;

TEST(ParseThreadCount, AcceptsOneToTheLimit) {
  EXPECT_EQ(ParseThreadCount("1"), 1);
  EXPECT_EQ(ParseThreadCount("2"), 2);
  EXPECT_EQ(ParseThreadCount(std::to_string(kMaxThreads)), kMaxThreads);
}

TEST(ParseThreadCount, RefusesNegativeHugeAndNonIntegers) {
  for (const char* bad :
       {"0", "-1", "100000", "1025", "1.5", "", "two", "1e3", "99999999999999999999"}) {
    const std::string message = ErrorOf([&] { ParseThreadCount(bad); });
    EXPECT_THAT(message, HasSubstr("--threads: got ")) << bad;
    EXPECT_THAT(message, HasSubstr("expected an integer from 1 to 1024 worker threads")) << bad;
    EXPECT_LT(message.size(), 120u) << message;  // not the largest double in 310 digits
  }
}

TEST(RequireAtMost, NamesTheCountAndTheLimit) {
  RequireAtMost(10, 10, "render.frames", "frames");
  EXPECT_THAT(ErrorOf([] { RequireAtMost(1'000'000'000, kMaxFrames, "render.frames", "frames"); }),
              HasSubstr("render.frames: got 1000000000 frames, expected at most 10000000 frames"));
}

}  // namespace
}  // namespace mmh
