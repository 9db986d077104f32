// Writes a synthetic take set as TUM + CSV files: the bundled demo takes in examples/ were made by
//   build/tools/make_example_takes OUT_DIR [takes] [reference_frames] [seed]
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "core/annotation.h"
#include "core/error.h"
#include "core/tum_io.h"
#include "tools/synthetic_takes.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: make_example_takes OUT_DIR [takes=4] [reference_frames=900] [seed=1]\n";
    return 2;
  }
  try {
    mmh::synthetic::TakeSetOptions options;
    options.takes = argc > 2 ? std::atoi(argv[2]) : 4;
    options.reference_frames = argc > 3 ? std::atoi(argv[3]) : 900;
    options.min_frames = options.reference_frames * 9 / 10;
    options.max_frames = options.reference_frames * 11 / 10;
    options.seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
    const auto set = mmh::synthetic::MakeTakeSet(options);
    const std::filesystem::path out = argv[1];
    std::filesystem::create_directories(out);
    for (std::size_t k = 0; k < set.takes.size(); ++k) {
      const std::string stem = "take_" + std::to_string(k + 1);
      mmh::WriteTum(
          out / (stem + ".tum"), set.takes[k],
          "synthetic take (tools/make_example_takes, seed " + std::to_string(options.seed) + ")");
      mmh::WriteAnnotationCsv(out / (stem + ".csv"), set.annotations[k]);
    }
  } catch (const mmh::InputError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}
