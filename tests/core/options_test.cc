// Tests of core/options.h: ToJson / FromJson of an Options struct with a nested struct and an enum.
#include "core/options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <utility>

#include "core/error.h"

namespace mmh::options_test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using json = nlohmann::json;

enum class Weight { kLinear, kSmoothstep };

std::span<const std::pair<Weight, const char*>> EnumNames(Weight) {
  static constexpr std::pair<Weight, const char*> kNames[] = {{Weight::kLinear, "linear"},
                                                              {Weight::kSmoothstep, "smoothstep"}};
  return kNames;
}

static_assert(NamedEnum<Weight>);

struct BlendOptions {
  int window = 15;                  // frames
  Weight weight = Weight::kLinear;  // blend weight shape
  template <class V>
  void VisitFields(V& v) {
    v("window", window);
    v("weight", weight);
  }
};

struct TestOptions {
  double lambda = 2.5;
  int min_length = 60;
  bool enabled = true;
  std::string name = "default";
  Weight shape = Weight::kSmoothstep;
  float gain = 0.5f;
  BlendOptions blend;
  template <class V>
  void VisitFields(V& v) {
    v("lambda", lambda);
    v("min_length", min_length);
    v("enabled", enabled);
    v("name", name);
    v("shape", shape);
    v("gain", gain);
    v("blend", blend);
  }
  void Validate(const std::string& prefix) const {
    if (!(lambda >= 0.0)) ThrowBadValue(prefix + ".lambda", FormatNumber(lambda), "a number >= 0");
  }
};

// Integer field types of every width and signedness.
struct CountOptions {
  std::size_t max_frames = 1000;
  std::uint64_t seed = 1;
  std::int64_t offset = 0;
  std::uint32_t count32 = 0;
  unsigned char byte = 0;
  int plain = 0;
  template <class V>
  void VisitFields(V& v) {
    v("max_frames", max_frames);
    v("seed", seed);
    v("offset", offset);
    v("count32", count32);
    v("byte", byte);
    v("plain", plain);
  }
  void Validate(const std::string&) const {}
};

// A default list of one element (built with push_back: from an initializer list GCC 12 warns,
// wrongly, that the element's copy may be uninitialised).
std::vector<BlendOptions> OneBlend() {
  std::vector<BlendOptions> blends;
  blends.push_back({3, Weight::kSmoothstep});
  return blends;
}

// A list of nested structs (a JSON array of objects).
struct ListOptions {
  std::vector<BlendOptions> blends = OneBlend();
  int after = 1;
  template <class V>
  void VisitFields(V& v) {
    v("blends", blends);
    v("after", after);
  }
};

const ConfigSource kSource{"configs/test.json"};

template <class T>
std::string FromJsonError(const json& j, const std::string& key_path = "montage") {
  T options;
  try {
    FromJson(j, key_path, kSource, &options);
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "FromJson threw a non-InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "FromJson accepted " << j.dump();
  return "";
}

TEST(Options, EnumNameLooksUpNames) {
  EXPECT_STREQ(EnumName(Weight::kLinear), "linear");
  EXPECT_STREQ(EnumName(Weight::kSmoothstep), "smoothstep");
}

TEST(Options, ToJsonGivesEveryDefault) {
  const json expected = {{"lambda", 2.5},
                         {"min_length", 60},
                         {"enabled", true},
                         {"name", "default"},
                         {"shape", "smoothstep"},
                         {"gain", 0.5},
                         {"blend", {{"window", 15}, {"weight", "linear"}}}};
  EXPECT_EQ(ToJson(TestOptions{}), expected) << ToJson(TestOptions{}).dump();
  // Integers stay integers in the resolved config.
  EXPECT_TRUE(ToJson(TestOptions{})["min_length"].is_number_integer());
}

TEST(Options, FromJsonOfEmptyObjectKeepsDefaults) {
  TestOptions options;
  options.lambda = 9;  // FromJson must not reset what is not given
  FromJson(json::object(), "montage", kSource, &options);
  EXPECT_EQ(options.lambda, 9);
  EXPECT_EQ(options.min_length, 60);
  EXPECT_EQ(options.name, "default");
}

TEST(Options, FromJsonKeepsDefaultsForMissingKeys) {
  TestOptions options;
  FromJson(json{{"lambda", 3}, {"blend", {{"window", 9}}}}, "montage", kSource, &options);
  EXPECT_EQ(options.lambda, 3.0);
  EXPECT_EQ(options.blend.window, 9);
  // Untouched:
  EXPECT_EQ(options.min_length, 60);
  EXPECT_TRUE(options.enabled);
  EXPECT_EQ(options.name, "default");
  EXPECT_EQ(options.shape, Weight::kSmoothstep);
  EXPECT_EQ(options.gain, 0.5f);
  EXPECT_EQ(options.blend.weight, Weight::kLinear);
}

TEST(Options, RoundTripThroughJson) {
  TestOptions options;
  options.lambda = 0.1 + 0.2;
  options.min_length = -3;
  options.enabled = false;
  options.name = "take \"one\"";
  options.shape = Weight::kLinear;
  options.gain = 0.125f;
  options.blend.window = 31;
  options.blend.weight = Weight::kSmoothstep;
  const json j = ToJson(options);
  TestOptions read;
  FromJson(j, "montage", kSource, &read);
  EXPECT_EQ(read.lambda, options.lambda);
  EXPECT_EQ(read.min_length, -3);
  EXPECT_FALSE(read.enabled);
  EXPECT_EQ(read.name, options.name);
  EXPECT_EQ(read.shape, Weight::kLinear);
  EXPECT_EQ(read.gain, 0.125f);
  EXPECT_EQ(read.blend.window, 31);
  EXPECT_EQ(read.blend.weight, Weight::kSmoothstep);
  // And serialising the text form and parsing it again gives the same JSON.
  EXPECT_EQ(json::parse(j.dump()), j);
}

TEST(Options, IntegerAcceptedForFloatingPointField) {
  TestOptions options;
  FromJson(json{{"lambda", 4}, {"gain", 2}}, "montage", kSource, &options);
  EXPECT_EQ(options.lambda, 4.0);
  EXPECT_EQ(options.gain, 2.0f);
}

TEST(Options, NumberOutOfRangeForFloatFieldIsRejected) {
  // 1e300 does not fit a float: it must not silently become infinity.
  TestOptions options;
  try {
    FromJson(json{{"gain", 1e300}}, "montage", kSource, &options);
    EXPECT_TRUE(std::isfinite(options.gain))
        << "1e300 was read into a float field as " << options.gain;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'montage.gain'"));
  }
}

TEST(Options, UnknownKeyNamesFullPathAndSuggests) {
  const std::string message = FromJsonError<TestOptions>(json{{"lamda", 3}});
  EXPECT_THAT(message, HasSubstr("configs/test.json"));
  EXPECT_THAT(message, HasSubstr("'montage.lamda'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'lambda'"));
  EXPECT_THAT(message, HasSubstr("unknown"));
}

TEST(Options, UnknownNestedKeyNamesFullPathAndSuggests) {
  const std::string message = FromJsonError<TestOptions>(json{{"blend", {{"widow", 3}}}});
  EXPECT_THAT(message, HasSubstr("'montage.blend.widow'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'window'"));
  // Known keys at that level are listed.
  EXPECT_THAT(message, HasSubstr("window, weight"));
}

TEST(Options, UnknownKeyWithoutCloseNameHasNoSuggestion) {
  const std::string message = FromJsonError<TestOptions>(json{{"completely_different", 1}});
  EXPECT_THAT(message, HasSubstr("'montage.completely_different'"));
  EXPECT_THAT(message, Not(HasSubstr("did you mean")));
  EXPECT_THAT(message, HasSubstr("lambda"));
}

TEST(Options, UnknownKeyWithEmptyKeyPath) {
  const std::string message = FromJsonError<TestOptions>(json{{"enabeld", true}}, "");
  EXPECT_THAT(message, HasSubstr("'enabeld'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'enabled'"));
}

TEST(Options, StringForNumberIsRejected) {
  const std::string message = FromJsonError<TestOptions>(json{{"lambda", "fast"}});
  EXPECT_THAT(message, HasSubstr("configs/test.json"));
  EXPECT_THAT(message, HasSubstr("'montage.lambda'"));
  EXPECT_THAT(message, HasSubstr("\"fast\""));
  EXPECT_THAT(message, HasSubstr("expected a number"));
}

TEST(Options, FloatForIntegerIsRejected) {
  const std::string message = FromJsonError<TestOptions>(json{{"min_length", 2.5}});
  EXPECT_THAT(message, HasSubstr("'montage.min_length'"));
  EXPECT_THAT(message, HasSubstr("2.5"));
  EXPECT_THAT(message, HasSubstr("expected an integer"));

  const std::string nested = FromJsonError<TestOptions>(json{{"blend", {{"window", 1.5}}}});
  EXPECT_THAT(nested, HasSubstr("'montage.blend.window'"));
  EXPECT_THAT(nested, HasSubstr("1.5"));
  EXPECT_THAT(nested, HasSubstr("an integer"));

  EXPECT_THAT(FromJsonError<TestOptions>(json{{"min_length", "60"}}), HasSubstr("an integer"));
}

TEST(Options, UnknownEnumNameIsRejected) {
  const std::string message = FromJsonError<TestOptions>(json{{"blend", {{"weight", "cubic"}}}});
  EXPECT_THAT(message, HasSubstr("'montage.blend.weight'"));
  EXPECT_THAT(message, HasSubstr("\"cubic\""));
  EXPECT_THAT(message, HasSubstr("one of linear, smoothstep"));
  // A number for an enum, and a case mismatch.
  EXPECT_THAT(FromJsonError<TestOptions>(json{{"shape", 1}}),
              HasSubstr("one of linear, smoothstep"));
  EXPECT_THAT(FromJsonError<TestOptions>(json{{"shape", "Linear"}}), HasSubstr("\"Linear\""));
}

TEST(Options, OtherWrongTypesAreRejected) {
  const std::string boolean = FromJsonError<TestOptions>(json{{"enabled", 1}});
  EXPECT_THAT(boolean, HasSubstr("'montage.enabled'"));
  EXPECT_THAT(boolean, HasSubstr("true or false"));
  EXPECT_THAT(FromJsonError<TestOptions>(json{{"enabled", "true"}}), HasSubstr("true or false"));

  const std::string str = FromJsonError<TestOptions>(json{{"name", 3}});
  EXPECT_THAT(str, HasSubstr("'montage.name'"));
  EXPECT_THAT(str, HasSubstr("a string"));

  const std::string nested = FromJsonError<TestOptions>(json{{"blend", 3}});
  EXPECT_THAT(nested, HasSubstr("'montage.blend'"));
  EXPECT_THAT(nested, HasSubstr("an object"));

  const std::string top = FromJsonError<TestOptions>(json::array({1, 2}));
  EXPECT_THAT(top, HasSubstr("'montage'"));
  EXPECT_THAT(top, HasSubstr("[1,2]"));

  EXPECT_THAT(FromJsonError<TestOptions>(json{{"lambda", nullptr}}), HasSubstr("null"));
  EXPECT_THAT(FromJsonError<TestOptions>(json{{"lambda", true}}), HasSubstr("a number"));
}

TEST(Options, IntegerOutOfRangeIsRejected) {
  const std::string message = FromJsonError<TestOptions>(json{{"min_length", 3000000000LL}});
  EXPECT_THAT(message, HasSubstr("'montage.min_length'"));
  EXPECT_THAT(message, HasSubstr("3000000000"));
  EXPECT_THAT(FromJsonError<CountOptions>(json{{"byte", 256}}), HasSubstr("'montage.byte'"));
  EXPECT_THAT(FromJsonError<CountOptions>(json{{"count32", -1}}), HasSubstr("'montage.count32'"));
}

TEST(Options, HugeUnsignedValueIsRejectedForSignedField) {
  // 2^64 - 1 is a JSON unsigned integer; it must not wrap round to -1 in an int field.
  const json j = json::parse(R"({"plain": 18446744073709551615})");
  const std::string message = FromJsonError<CountOptions>(j);
  EXPECT_THAT(message, HasSubstr("'montage.plain'"));
  const json j64 = json::parse(R"({"offset": 9223372036854775808})");
  EXPECT_THAT(FromJsonError<CountOptions>(j64), HasSubstr("'montage.offset'"));
}

TEST(Options, SixtyFourBitIntegerFieldsAreRead) {
  CountOptions options;
  FromJson(json{{"offset", -5}, {"count32", 4000000000LL}, {"byte", 255}}, "montage", kSource,
           &options);
  EXPECT_EQ(options.offset, -5);
  EXPECT_EQ(options.count32, 4000000000u);
  EXPECT_EQ(options.byte, 255);
}

TEST(Options, SizeTAndUint64FieldsAreRead) {
  // std::size_t is the natural type of counts (frames, windows); it must be settable.
  CountOptions options;
  try {
    FromJson(json{{"max_frames", 5}}, "montage", kSource, &options);
    EXPECT_EQ(options.max_frames, 5u);
  } catch (const InputError& e) {
    ADD_FAILURE() << "size_t field rejected 5: " << e.what();
  }
  try {
    FromJson(json::parse(R"({"seed": 18446744073709551615})"), "montage", kSource, &options);
    EXPECT_EQ(options.seed, std::numeric_limits<std::uint64_t>::max());
  } catch (const InputError& e) {
    ADD_FAILURE() << "uint64 field rejected 2^64-1: " << e.what();
  }
  // Negative values are still rejected.
  EXPECT_THAT(FromJsonError<CountOptions>(json{{"max_frames", -1}}),
              HasSubstr("'montage.max_frames'"));
}

TEST(Options, ListOfStructsRoundTripsAndReplacesTheDefaultList) {
  ListOptions options;
  EXPECT_EQ(ToJson(options),
            json::parse(R"({"blends": [{"window": 3, "weight": "smoothstep"}], "after": 1})"));
  FromJson(json::parse(R"({"blends": [{"window": 7}, {"weight": "smoothstep"}]})"), "", kSource,
           &options);
  ASSERT_EQ(options.blends.size(), 2u);
  EXPECT_EQ(options.blends[0].window, 7);
  EXPECT_EQ(options.blends[0].weight, Weight::kLinear);  // the element's default, not the list's
  EXPECT_EQ(options.blends[1].window, 15);
  EXPECT_EQ(options.blends[1].weight, Weight::kSmoothstep);
  ListOptions back;
  FromJson(ToJson(options), "", kSource, &back);
  EXPECT_EQ(ToJson(back), ToJson(options));
  FromJson(json::parse(R"({"blends": []})"), "", kSource, &back);
  EXPECT_TRUE(back.blends.empty());
  EXPECT_EQ(ToJson(back)["blends"], json::array());
}

TEST(Options, ListOfStructsErrorsNameTheElement) {
  const std::string not_array =
      FromJsonError<ListOptions>(json::parse(R"({"blends": {"window": 3}})"));
  EXPECT_THAT(not_array, HasSubstr("montage.blends"));
  EXPECT_THAT(not_array, HasSubstr("an array of objects"));
  const std::string unknown =
      FromJsonError<ListOptions>(json::parse(R"({"blends": [{}, {"windw": 3}]})"));
  EXPECT_THAT(unknown, HasSubstr("montage.blends[1].windw"));
  EXPECT_THAT(unknown, HasSubstr("did you mean 'window'"));
  const std::string wrong_type =
      FromJsonError<ListOptions>(json::parse(R"({"blends": [{"window": "wide"}]})"));
  EXPECT_THAT(wrong_type, HasSubstr("montage.blends[0].window"));
  EXPECT_THAT(FromJsonError<ListOptions>(json::parse(R"({"blends": [3]})")),
              HasSubstr("montage.blends[0]"));
}

TEST(Options, SuggestName) {
  using options_internal::SuggestName;
  const std::vector<std::string> known = {"lambda", "min_length", "window"};
  EXPECT_EQ(SuggestName("lamda", known), "lambda");
  EXPECT_EQ(SuggestName("lambda_", known), "lambda");
  EXPECT_EQ(SuggestName("minlenght", known), "");  // distance 3
  EXPECT_EQ(SuggestName("min_lenght", known), "min_length");
  EXPECT_EQ(SuggestName("xyz", known), "");
  EXPECT_EQ(SuggestName("anything", {}), "");
}

TEST(Options, JoinNames) {
  using options_internal::JoinNames;
  EXPECT_EQ(JoinNames({}), "");
  EXPECT_EQ(JoinNames({"a"}), "a");
  EXPECT_EQ(JoinNames({"a", "b", "c"}), "a, b, c");
}

}  // namespace
}  // namespace mmh::options_test
