// Tests of core/config.h: loading JSON files, --set overrides, Get<Options>, section checks.
#include "core/config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <string>
#include <utility>

#include "core/error.h"
#include "tests/test_util.h"

namespace mmh::config_test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using json = nlohmann::json;

enum class Weight { kLinear, kSmoothstep };

std::span<const std::pair<Weight, const char*>> EnumNames(Weight) {
  static constexpr std::pair<Weight, const char*> kNames[] = {{Weight::kLinear, "linear"},
                                                              {Weight::kSmoothstep, "smoothstep"}};
  return kNames;
}

struct BlendOptions {
  int window = 15;
  Weight weight = Weight::kLinear;
  template <class V>
  void VisitFields(V& v) {
    v("window", window);
    v("weight", weight);
  }
};

struct MontageOptions {
  double lambda = 2.5;
  int min_length = 60;
  bool enabled = true;
  std::string name = "default";
  BlendOptions blend;
  template <class V>
  void VisitFields(V& v) {
    v("lambda", lambda);
    v("min_length", min_length);
    v("enabled", enabled);
    v("name", name);
    v("blend", blend);
  }
  void Validate(const std::string& prefix) const {
    if (!(lambda >= 0.0)) ThrowBadValue(prefix + ".lambda", FormatNumber(lambda), "a number >= 0");
  }
};

using test_util::TempDir;

fs::path WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return path;
}

template <class F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-InputError: " << e.what();
    return "";
  }
  ADD_FAILURE() << "did not throw";
  return "";
}

// ----------------------------------------------------------------------------------------------
// Defaults and files

TEST(Config, EmptyConfigGivesDefaults) {
  const Config config;
  const auto options = config.Get<MontageOptions>("montage");
  EXPECT_EQ(options.lambda, 2.5);
  EXPECT_EQ(options.blend.window, 15);
  EXPECT_TRUE(config.root().is_object());
  EXPECT_TRUE(config.root().empty());
}

TEST(Config, LoadReadsSectionsAndKeepsDefaults) {
  TempDir dir;
  const fs::path path = WriteText(dir / "a.json", R"({
  "montage": {"lambda": 4, "blend": {"weight": "smoothstep"}},
  "other": {"anything": 1}
})");
  const Config config = Config::Load(path);
  const auto options = config.Get<MontageOptions>("montage");
  EXPECT_EQ(options.lambda, 4.0);
  EXPECT_EQ(options.blend.weight, Weight::kSmoothstep);
  EXPECT_EQ(options.blend.window, 15);
  EXPECT_EQ(options.min_length, 60);
  // A section that is absent gives the defaults.
  EXPECT_EQ(config.Get<MontageOptions>("absent").lambda, 2.5);
}

TEST(Config, UnknownKeyInFileNamesFileKeyAndSuggestion) {
  TempDir dir;
  const fs::path path = WriteText(dir / "typo.json", R"({"montage": {"blend": {"windw": 5}}})");
  const Config config = Config::Load(path);
  const std::string message = InputErrorOf([&] { config.Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr(path.string()));
  EXPECT_THAT(message, HasSubstr("'montage.blend.windw'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'window'"));
}

TEST(Config, WrongTypeInFileNamesFileKeyValueAndExpectation) {
  TempDir dir;
  const fs::path path = WriteText(dir / "type.json", R"({"montage": {"min_length": 60.5}})");
  const std::string message =
      InputErrorOf([&] { Config::Load(path).Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr(path.string()));
  EXPECT_THAT(message, HasSubstr("'montage.min_length'"));
  EXPECT_THAT(message, HasSubstr("60.5"));
  EXPECT_THAT(message, HasSubstr("an integer"));
}

TEST(Config, ValidateIsCalledWithTheSectionPrefix) {
  TempDir dir;
  const fs::path path = WriteText(dir / "v.json", R"({"montage": {"lambda": -1}})");
  const std::string message =
      InputErrorOf([&] { Config::Load(path).Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("montage.lambda"));
  EXPECT_THAT(message, HasSubstr("-1"));
}

TEST(Config, SectionThatIsNotAnObjectIsRejected) {
  TempDir dir;
  const fs::path path = WriteText(dir / "s.json", R"({"montage": 3})");
  const std::string message =
      InputErrorOf([&] { Config::Load(path).Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("'montage'"));
  EXPECT_THAT(message, HasSubstr("an object"));
}

TEST(Config, InvalidJsonNamesFileLineAndColumn) {
  TempDir dir;
  // Trailing comma: the parser fails at the '}' on line 4, column 3.
  const fs::path path = WriteText(dir / "bad.json",
                                  "{\n"
                                  "  \"montage\": {\n"
                                  "    \"lambda\": 4,\n"
                                  "  }\n"
                                  "}\n");
  const std::string message = InputErrorOf([&] { Config::Load(path); });
  EXPECT_THAT(message, HasSubstr(path.string() + ":4:3"));
  EXPECT_THAT(message, HasSubstr("invalid JSON"));
}

TEST(Config, InvalidJsonOnFirstLine) {
  TempDir dir;
  const fs::path path = WriteText(dir / "bad1.json", R"({"montage": tru})");
  const std::string message = InputErrorOf([&] { Config::Load(path); });
  // "tru}" fails at the '}' (column 16) or at the start of the literal (column 13).
  EXPECT_THAT(message, HasSubstr(path.string() + ":1:"));
  EXPECT_TRUE(message.find(":1:16") != std::string::npos ||
              message.find(":1:13") != std::string::npos)
      << message;
}

TEST(Config, InvalidJsonAfterCrlfLines) {
  TempDir dir;
  const fs::path path = WriteText(dir / "bad2.json", "{\r\n  \"a\": 1\r\n  \"b\": 2\r\n}\r\n");
  const std::string message = InputErrorOf([&] { Config::Load(path); });
  // Missing comma: fails at the string "b" on line 3 (columns 3 to 5).
  EXPECT_THAT(message, HasSubstr(path.string() + ":3:"));
}

TEST(Config, TruncatedJsonNamesFile) {
  TempDir dir;
  const fs::path path = WriteText(dir / "trunc.json", "{\"montage\": {\"lambda\": 4}\n");
  const std::string message = InputErrorOf([&] { Config::Load(path); });
  EXPECT_THAT(message, HasSubstr(path.string() + ":"));
  EXPECT_THAT(message, HasSubstr("invalid JSON"));
}

TEST(Config, EmptyFileIsAnInputError) {
  TempDir dir;
  const fs::path path = WriteText(dir / "empty.json", "");
  EXPECT_THAT(InputErrorOf([&] { Config::Load(path); }), HasSubstr(path.string()));
}

TEST(Config, NumberTooLargeForDoubleIsAnInputError) {
  // nlohmann throws out_of_range (not parse_error) for 1e999: it must still become an InputError.
  TempDir dir;
  const fs::path path = WriteText(dir / "huge.json", R"({"montage": {"lambda": 1e999}})");
  EXPECT_THAT(InputErrorOf([&] { Config::Load(path); }), HasSubstr(path.string()));
}

TEST(Config, TopLevelMustBeAnObject) {
  TempDir dir;
  const fs::path path = WriteText(dir / "array.json", "[1, 2]");
  const std::string message = InputErrorOf([&] { Config::Load(path); });
  EXPECT_THAT(message, HasSubstr(path.string()));
  EXPECT_THAT(message, HasSubstr("array"));
  EXPECT_THAT(message, HasSubstr("object"));
}

TEST(Config, MissingFileAndFolderAreInputErrors) {
  TempDir dir;
  EXPECT_THAT(InputErrorOf([&] { Config::Load(dir / "missing.json"); }),
              HasSubstr((dir / "missing.json").string()));
  fs::create_directory(dir / "folder.json");
  EXPECT_THAT(InputErrorOf([&] { Config::Load(dir / "folder.json"); }),
              HasSubstr((dir / "folder.json").string()));
}

// ----------------------------------------------------------------------------------------------
// --set

TEST(Config, SetParsesJsonValues) {
  Config config;
  config.Set("montage.lambda=3.5");
  config.Set("montage.min_length=61");
  config.Set("montage.enabled=false");
  config.Set("montage.name=\"quoted\"");
  config.Set("montage.blend={\"window\": 7, \"weight\": \"smoothstep\"}");
  EXPECT_TRUE(config.root()["montage"]["lambda"].is_number_float());
  EXPECT_TRUE(config.root()["montage"]["min_length"].is_number_integer());
  EXPECT_TRUE(config.root()["montage"]["enabled"].is_boolean());
  const auto options = config.Get<MontageOptions>("montage");
  EXPECT_EQ(options.lambda, 3.5);
  EXPECT_EQ(options.min_length, 61);
  EXPECT_FALSE(options.enabled);
  EXPECT_EQ(options.name, "quoted");
  EXPECT_EQ(options.blend.window, 7);
  EXPECT_EQ(options.blend.weight, Weight::kSmoothstep);
}

TEST(Config, SetTakesNonJsonAsBareString) {
  Config config;
  config.Set("montage.blend.weight=smoothstep");
  config.Set("montage.name=hello world");
  config.Set("montage.other=a=b");  // only the first '=' splits
  EXPECT_EQ(config.root()["montage"]["blend"]["weight"], "smoothstep");
  EXPECT_EQ(config.root()["montage"]["name"], "hello world");
  EXPECT_EQ(config.root()["montage"]["other"], "a=b");
  config.Set("montage.other=\"x\"");
  EXPECT_EQ(config.root()["montage"]["other"], "x");
}

TEST(Config, SetCreatesNestedPaths) {
  Config config;
  config.Set("montage.blend.window=9");
  ASSERT_TRUE(config.root().contains("montage"));
  ASSERT_TRUE(config.root()["montage"].is_object());
  ASSERT_TRUE(config.root()["montage"]["blend"].is_object());
  EXPECT_EQ(config.root()["montage"]["blend"]["window"], 9);
  const auto options = config.Get<MontageOptions>("montage");
  EXPECT_EQ(options.blend.window, 9);
  EXPECT_EQ(options.blend.weight, Weight::kLinear);
  EXPECT_EQ(options.lambda, 2.5);
}

TEST(Config, SetOverridesFileAndKeepsTheRest) {
  TempDir dir;
  const fs::path path =
      WriteText(dir / "base.json", R"({"montage": {"lambda": 4, "blend": {"window": 21}}})");
  Config config = Config::Load(path);
  config.Set("montage.blend.window=5");
  const auto options = config.Get<MontageOptions>("montage");
  EXPECT_EQ(options.lambda, 4.0);
  EXPECT_EQ(options.blend.window, 5);
  // The last --set of a key wins.
  config.Set("montage.blend.window=6");
  EXPECT_EQ(config.Get<MontageOptions>("montage").blend.window, 6);
}

TEST(Config, SetWrongTypeNamesTheAssignment) {
  Config config;
  config.Set("montage.lambda=fast");
  const std::string message = InputErrorOf([&] { config.Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("--set montage.lambda=fast"));
  EXPECT_THAT(message, HasSubstr("'montage.lambda'"));
  EXPECT_THAT(message, HasSubstr("\"fast\""));
  EXPECT_THAT(message, HasSubstr("a number"));
}

TEST(Config, SetUnknownKeyNamesTheAssignmentAndSuggests) {
  Config config;
  config.Set("montage.blend.widow=3");
  const std::string message = InputErrorOf([&] { config.Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("--set montage.blend.widow=3"));
  EXPECT_THAT(message, HasSubstr("'montage.blend.widow'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'window'"));
}

TEST(Config, SetErrorOnTopOfFileNamesBoth) {
  TempDir dir;
  const fs::path path = WriteText(dir / "base.json", R"({"montage": {"lambda": 4}})");
  Config config = Config::Load(path);
  config.Set("montage.blend.weight=cubic");
  const std::string message = InputErrorOf([&] { config.Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("--set montage.blend.weight=cubic"));
  EXPECT_THAT(message, HasSubstr("\"cubic\""));
  EXPECT_THAT(message, HasSubstr("one of linear, smoothstep"));
}

TEST(Config, SetOfAnEnumNameAsBareString) {
  Config config;
  config.Set("montage.blend.weight=smoothstep");
  EXPECT_EQ(config.Get<MontageOptions>("montage").blend.weight, Weight::kSmoothstep);
}

TEST(Config, MalformedAssignmentsAreRejected) {
  Config config;
  const std::string no_equals = InputErrorOf([&] { config.Set("montage.lambda"); });
  EXPECT_THAT(no_equals, HasSubstr("--set montage.lambda"));
  EXPECT_THAT(no_equals, HasSubstr("key.path=value"));

  EXPECT_THAT(InputErrorOf([&] { config.Set("=3"); }), HasSubstr("--set =3"));

  const std::string empty_key = InputErrorOf([&] { config.Set("montage..lambda=3"); });
  EXPECT_THAT(empty_key, HasSubstr("--set montage..lambda=3"));
  EXPECT_THAT(empty_key, HasSubstr("empty key"));
  EXPECT_THAT(InputErrorOf([&] { config.Set("montage.=3"); }), HasSubstr("empty key"));
  EXPECT_THAT(InputErrorOf([&] { config.Set(".montage=3"); }), HasSubstr("empty key"));
}

TEST(Config, SetThroughANonObjectIsRejected) {
  Config config;
  config.Set("montage.lambda=3");
  const std::string message = InputErrorOf([&] { config.Set("montage.lambda.x=1"); });
  EXPECT_THAT(message, HasSubstr("--set montage.lambda.x=1"));
  EXPECT_THAT(message, HasSubstr("non-object"));
}

TEST(Config, SetOfANumberTooLargeIsAnInputErrorOrString) {
  // "1e999" is not representable: it must not escape as a JSON library exception.
  Config config;
  try {
    config.Set("montage.lambda=1e999");
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--set montage.lambda=1e999"));
    return;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "Set threw a non-InputError: " << e.what();
    return;
  }
  // Accepted as something (e.g. the string "1e999"): then Get must reject it as an InputError.
  const std::string message = InputErrorOf([&] { config.Get<MontageOptions>("montage"); });
  EXPECT_THAT(message, HasSubstr("--set montage.lambda=1e999"));
}

TEST(Config, SourceOf) {
  TempDir dir;
  EXPECT_EQ(Config().SourceOf("montage").name, "config");
  const fs::path path = WriteText(dir / "c.json", R"({"montage": {}})");
  Config config = Config::Load(path);
  EXPECT_EQ(config.SourceOf("montage").name, path.string());
  config.Set("montage.lambda=1");
  EXPECT_THAT(config.SourceOf("montage").name, HasSubstr(path.string()));
  EXPECT_THAT(config.SourceOf("montage").name, HasSubstr("--set montage.lambda=1"));
  EXPECT_THAT(config.SourceOf("montage.lambda").name, HasSubstr("--set montage.lambda=1"));
  // An unrelated section is not attributed to that --set, nor a section sharing a name prefix.
  EXPECT_EQ(config.SourceOf("sim").name, path.string());
  EXPECT_EQ(config.SourceOf("montag").name, path.string());
}

TEST(Config, FolderOfIsTheFilesFolderUnlessASetGaveTheValue) {
  TempDir dir;
  EXPECT_EQ(Config().FolderOf("scene.objects"), fs::path());
  const fs::path path = WriteText(dir / "c.json", R"({"scene": {"objects": []}, "montage": {}})");
  Config config = Config::Load(path);
  EXPECT_EQ(config.FolderOf("scene.objects"), dir.path());
  config.Set("montage.lambda=1");
  EXPECT_EQ(config.FolderOf("scene.objects"), dir.path());
  config.Set("scene.objects=[]");
  EXPECT_EQ(config.FolderOf("scene.objects"), fs::path());
  EXPECT_EQ(config.FolderOf("scene"), fs::path());  // a --set below the key
  Config above = Config::Load(path);
  above.Set("scene={}");
  EXPECT_EQ(above.FolderOf("scene.objects"), fs::path());
}

// ----------------------------------------------------------------------------------------------
// RequireOnlySections

TEST(Config, RequireOnlySectionsAcceptsKnownSections) {
  TempDir dir;
  const fs::path path = WriteText(dir / "ok.json", R"({"montage": {}, "metrics": {}})");
  const Config config = Config::Load(path);
  EXPECT_NO_THROW(config.RequireOnlySections({"montage", "metrics", "sim"}));
  EXPECT_NO_THROW(Config().RequireOnlySections({}));
}

TEST(Config, RequireOnlySectionsRejectsUnknownSection) {
  TempDir dir;
  const fs::path path = WriteText(dir / "bad.json", R"({"montage": {}, "metrcs": {}})");
  const Config config = Config::Load(path);
  const std::string message = InputErrorOf([&] {
    config.RequireOnlySections({"montage", "metrics"});
  });
  EXPECT_THAT(message, HasSubstr(path.string()));
  EXPECT_THAT(message, HasSubstr("'metrcs'"));
  EXPECT_THAT(message, HasSubstr("did you mean 'metrics'"));
  EXPECT_THAT(message, HasSubstr("montage, metrics"));
}

TEST(Config, RequireOnlySectionsNamesTheSetThatAddedIt) {
  Config config;
  config.Set("montage.lambda=1");
  config.Set("simulation.seed=3");
  const std::string message = InputErrorOf([&] { config.RequireOnlySections({"montage"}); });
  EXPECT_THAT(message, HasSubstr("--set simulation.seed=3"));
  EXPECT_THAT(message, HasSubstr("'simulation'"));
  EXPECT_THAT(message, Not(HasSubstr("did you mean")));
}

}  // namespace
}  // namespace mmh::config_test
