// Tests of core/error_text.h: values from outside are escaped and shortened in messages.
#include "core/error_text.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace mmh {
namespace {

using ::testing::HasSubstr;

TEST(EscapeForMessage, KeepsPrintableTextAndValidUtf8) {
  EXPECT_EQ(EscapeForMessage("timestamp,value"), "timestamp,value");
  EXPECT_EQ(EscapeForMessage("1 \xC2\xB1 0.01 \xE2\x82\xAC"), "1 \xC2\xB1 0.01 \xE2\x82\xAC");
}

TEST(EscapeForMessage, EscapesControlBytesInvalidUtf8AndTheByteOrderMark) {
  EXPECT_EQ(EscapeForMessage(std::string("a\0b\x1B[2J\r\n\t", 10)), "a\\x00b\\x1B[2J\\r\\n\\t");
  EXPECT_EQ(EscapeForMessage("\xFF\xFE"), "\\xFF\\xFE");
  EXPECT_EQ(EscapeForMessage("\xC0\xAF"), "\\xC0\\xAF");           // overlong '/'
  EXPECT_EQ(EscapeForMessage("\xED\xA0\x80"), "\\xED\\xA0\\x80");  // a surrogate
  EXPECT_EQ(EscapeForMessage("\xE2\x82"), "\\xE2\\x82");           // cut sequence
  // Two strings that look the same on a terminal must differ in the message.
  EXPECT_EQ(EscapeForMessage("\xEF\xBB\xBFtimestamp"), "\\uFEFF (a byte-order mark)timestamp");
}

TEST(EscapeForMessage, ShortensLongTextAndSaysItsLength) {
  const std::string field(2'000'000, 'z');
  const std::string shown = EscapeForMessage(field);
  EXPECT_EQ(shown, std::string(48, 'z') + "... (2000000 bytes in all)");
  EXPECT_EQ(Quote(field, 3), "'zzz... (2000000 bytes in all)'");
  // Escapes count as one character each: binary garbage stays short too.
  const std::string garbage(1000, '\x01');
  EXPECT_LE(EscapeForMessage(garbage).size(), 48u * 4 + 30);
}

TEST(DescribeBadValue, EscapesAndShortensTheValue) {
  const std::string message =
      DescribeBadValue("f.csv:3", std::string(10'000, 'v') + "\x07", "a number");
  EXPECT_LT(message.size(), 250u);
  EXPECT_THAT(message, HasSubstr("f.csv:3: got vvvv"));
  EXPECT_THAT(message, HasSubstr("(10001 bytes in all), expected a number"));
}

}  // namespace
}  // namespace mmh
