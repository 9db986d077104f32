// libFuzzer target: annotation CSVs (core/annotation.h), checked and written back.
#include <cstddef>
#include <cstdint>

#include "core/annotation.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const auto path = fuzz::WriteInput("annotation.csv", {reinterpret_cast<const char*>(data), size});
  fuzz::ExpectReadOrInputError([&] {
    const Annotation a = ReadAnnotationCsv(path);
    ValidateAnnotation(a, path.string());
    WriteAnnotationCsv(fuzz::ScratchDir() / "written.csv", a);
    const Annotation again = ReadAnnotationCsv(fuzz::ScratchDir() / "written.csv");
    if (again.values != a.values) __builtin_trap();
  });
  return 0;
}
