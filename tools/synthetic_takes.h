// Synthetic takes of a scripted story with annotations, for benchmarks and the bundled demo, until
// sim/ provides real simulated performances. A take is the story's path performed with its own
// timing (a smooth random speed profile, length drawn from a range), style (bounce, yaw swings),
// tracking noise and one or two localised flaws (a stretch off the path and wobbling); the
// annotation follows the take's quality (disliking the flaws), with slow drift and noise, and is
// recorded with the annotator's reaction delay. Deterministic per seed on every platform (own
// normal variates, no std::normal_distribution).
#pragma once

#include <cstdint>
#include <vector>

#include "core/annotation.h"
#include "core/trajectory.h"

namespace mmh::synthetic {

struct TakeSetOptions {
  int takes = 10;               // m
  int reference_frames = 3000;  // frames of take 0
  int min_frames = 2700;        // other takes: uniform in [min_frames, max_frames]
  int max_frames = 3300;
  double frame_rate = 30.0;        // Hz
  double reaction_time = 0.3;      // s, delay of the recorded annotation
  double position_noise = 0.0015;  // m, per axis
  double rotation_noise = 0.008;   // rad, per axis
  std::uint64_t seed = 1;
};

struct TakeSet {
  std::vector<Trajectory> takes;
  std::vector<Annotation> annotations;
};

TakeSet MakeTakeSet(const TakeSetOptions& options);

}  // namespace mmh::synthetic
