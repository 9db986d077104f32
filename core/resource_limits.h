// Limits on what a run may ask for, checked up front: an input that would need absurd memory or
// time (10^9 frames, 10^6 animators, a 20000 x 20000 image, 100000 threads) is refused with a
// clear error before any work starts, instead of being attempted until the machine gives up.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace mmh {

// Largest meaningful translation coordinate [m]: 1000 km, far beyond any recording of a hand-held
// object (or a vehicle in a city), yet small enough that every cost of the montage (squared
// distances summed over hours of frames, paper eq. 5) stays finite in double precision. Readers
// reject coordinates beyond it (1e200 m made the DTW's costs infinite and crashed it).
inline constexpr double kMaxTranslationMetres = 1e6;

// Worker threads: more than any machine the harness runs on (oneTBB clamps to the cores anyway;
// a huge value is a typo, e.g. 100000 for 10).
inline constexpr int kMaxThreads = 1024;
// Frames of one take or sequence: 10^7 is 92 hours at 30 Hz.
inline constexpr std::int64_t kMaxFrames = 10'000'000;
// Image side [px]: as PinholeIntrinsics::Validate and the image readers.
inline constexpr int kMaxImageSide = 16384;
// Simulated animators (or scorers) of one study: the paper had 20 (and 42 scorers).
inline constexpr std::int64_t kMaxPeople = 100'000;

// Parses a --threads value: an integer in [1, kMaxThreads] (no --threads: all cores). InputError
// naming `flag`, the (quoted, shortened) value and the expectation otherwise.
int ParseThreadCount(std::string_view text, const std::string& flag = "--threads");

// InputError naming `where` if `count` exceeds `limit` (`what` e.g. "frames").
void RequireAtMost(std::int64_t count, std::int64_t limit, const std::string& where,
                   const std::string& what);

}  // namespace mmh
