// libFuzzer target: story files (people/story.h, configs/stories/*.json), read and validated
// against the default table, then every object's beat polylines walked as the animators do.
#include <cstddef>
#include <cstdint>

#include "fuzz/fuzz_input.h"
#include "people/story.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("story.json", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const people::Story story = people::LoadStory(path);
    for (const people::StoryObject& object : story.objects) {
      for (int i = 0; i < static_cast<int>(object.beats.size()); ++i) {
        const auto polyline = object.BeatPolyline(i);
        if (!(people::PolylineLength(polyline) >= 0)) __builtin_trap();
      }
    }
  });
  return 0;
}
