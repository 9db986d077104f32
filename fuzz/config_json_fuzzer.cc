// libFuzzer target: JSON configs and --set values (core/config.h, core/json_text.h). The input is
// a config file, optionally followed by "\n--set\n" and one assignment per line; the result is
// read into a real Options struct (the montage's), as a command would.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "core/config.h"
#include "fuzz/fuzz_input.h"
#include "montage/compose.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  // (Not a structured binding: clang 14 cannot capture one in the lambda below.)
  const auto parts = fuzz::SplitInput({reinterpret_cast<const char*>(data), size}, "\n--set\n");
  const std::string_view file = parts.first, sets = parts.second;
  const auto path = fuzz::WriteInput("config.json", file);
  fuzz::ExpectReadOrInputError([&] {
    Config config = Config::Load(path);
    std::istringstream lines{std::string(sets)};
    for (std::string line; std::getline(lines, line);) config.Set(line);
    config.RequireOnlySections({"montage"});
    config.Get<montage::ComposeOptions>("montage");
  });
  return 0;
}
