// The tracker's status names, as the tables write and read them.
#include "track/track_status.h"

#include <gtest/gtest.h>

namespace mmh::track {
namespace {

TEST(TrackStatus, NamesReadBackAndNothingElseDoes) {
  for (const TrackStatus s : {TrackStatus::kTracked, TrackStatus::kPredicted, TrackStatus::kLost}) {
    ASSERT_TRUE(TrackStatusFromName(TrackStatusName(s)).has_value());
    EXPECT_EQ(*TrackStatusFromName(TrackStatusName(s)), s);
  }
  EXPECT_STREQ(TrackStatusName(TrackStatus::kPredicted), "predicted");
  for (const char* other : {"", "Tracked", "lost ", "?", "track"}) {
    EXPECT_FALSE(TrackStatusFromName(other).has_value()) << other;
  }
}

}  // namespace
}  // namespace mmh::track
