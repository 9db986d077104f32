// libFuzzer target: a study's CSVs (study/study_data.h): the input is split at "\n----\n" into
// rankings.csv, comparisons.csv and segment_costs.csv (absent when its part is empty), read and
// validated with and without tied ranks; what reads is written back and must read the same.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fuzz/fuzz_input.h"
#include "study/study_data.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mmh;
  const std::filesystem::path dir = fuzz::ScratchDir() / "study";
  fuzz::WriteParts({reinterpret_cast<const char*>(data), size}, "study",
                   {study::kRankingsFile, study::kComparisonsFile, study::kSegmentCostsFile});
  for (const bool ties : {false, true}) {
    fuzz::ExpectReadOrInputError([&] {
      study::StudyDataOptions options;
      options.allow_tied_ranks = ties;
      const study::StudyData read = study::ReadStudyData(dir, options);
      const std::filesystem::path again_dir = fuzz::ScratchDir() / "study_again";
      std::filesystem::remove_all(again_dir);
      study::WriteStudyData(again_dir, read);
      const study::StudyData again = study::ReadStudyData(again_dir, options);
      if (study::RankingsToCsv(again.rankings) != study::RankingsToCsv(read.rankings) ||
          study::ComparisonsToCsv(again.comparisons) != study::ComparisonsToCsv(read.comparisons) ||
          study::SegmentCostsToCsv(again.segment_costs) !=
              study::SegmentCostsToCsv(read.segment_costs)) {
        __builtin_trap();
      }
    });
  }
  return 0;
}
