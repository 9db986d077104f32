#include "tools/synthetic_takes.h"

#include <algorithm>
#include <cmath>

namespace mmh::synthetic {
namespace {

// SplitMix64 and Box-Muller: the same numbers on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double Uniform() { return (Next() >> 11) * 0x1.0p-53; }
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  double Normal() {
    const double u1 = std::max(Uniform(), 1e-300), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::uint64_t state_;
};

// A smooth random function on [0, 1]: a sum of a few sinusoids with random phases.
struct SmoothNoise {
  double amplitude[4], frequency[4], phase[4];
  SmoothNoise(Random& random, double scale) {
    for (int k = 0; k < 4; ++k) {
      amplitude[k] = scale * random.Uniform(0.3, 1.0) / (k + 1);
      frequency[k] = random.Uniform(1.0, 3.0) * (k + 1);
      phase[k] = random.Uniform(0.0, 2 * M_PI);
    }
  }
  double operator()(double u) const {
    double v = 0;
    for (int k = 0; k < 4; ++k)
      v += amplitude[k] * std::sin(2 * M_PI * frequency[k] * u + phase[k]);
    return v;
  }
};

struct Style {
  double bounce, yaw_swing, jump_height, limp;
};

// The story's pose at progress u in [0, 1] (table frame, metres): marching back and forth, a walk
// around the castle, jumping with joy, slipping and falling, limping back.
Rigid3 StoryPose(double u, const Style& style) {
  double x = 0, y = 0, z = 0.03, yaw = 0, roll = 0;
  if (u < 0.25) {  // marching back and forth: three passes
    const double v = u / 0.25;
    x = 0.2 * std::sin(3 * M_PI * v);
    yaw = std::cos(3 * M_PI * v) > 0 ? 0.0 : M_PI;
    z += style.bounce * std::abs(std::sin(40 * M_PI * v));
  } else if (u < 0.5) {  // the walk around the castle
    const double v = (u - 0.25) / 0.25;
    const double a = 2 * M_PI * v;
    x = 0.2 * std::cos(a);
    y = 0.15 * std::sin(a);
    yaw = a + M_PI / 2 + style.yaw_swing * std::sin(12 * a);
    z += style.bounce * std::abs(std::sin(30 * M_PI * v));
  } else if (u < 0.65) {  // jumping with joy
    const double v = (u - 0.5) / 0.15;
    x = 0.2 - 0.25 * v;
    y = 0.05 * std::sin(2 * M_PI * v);
    yaw = M_PI + style.yaw_swing * std::sin(6 * M_PI * v);
    z += style.jump_height * std::abs(std::sin(5 * M_PI * v));
  } else if (u < 0.75) {  // the banana peel: slip and fall
    const double v = (u - 0.65) / 0.1;
    x = -0.05 - 0.05 * v;
    yaw = M_PI;
    roll = (M_PI / 2) * std::clamp(2 * v - 0.4, 0.0, 1.0);
  } else {  // getting up, limping back
    const double v = (u - 0.75) / 0.25;
    x = -0.1 + 0.3 * v;
    yaw = 0.0;
    roll = (M_PI / 2) * std::clamp(1 - 4 * v, 0.0, 1.0);
    z += style.limp * std::abs(std::sin(20 * M_PI * v)) * (std::sin(10 * M_PI * v) > 0 ? 1 : 0.3);
  }
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return Rigid3(q, Eigen::Vector3d(x, y, z));
}

}  // namespace

TakeSet MakeTakeSet(const TakeSetOptions& options) {
  Random random(options.seed);
  TakeSet set;
  const double period = 1.0 / options.frame_rate;
  const int shift = static_cast<int>(std::lround(options.reaction_time / period));
  for (int k = 0; k < options.takes; ++k) {
    const int frames =
        k == 0 ? options.reference_frames
               : static_cast<int>(random.Uniform(options.min_frames, options.max_frames + 1));
    const Style style{random.Uniform(0.005, 0.02), random.Uniform(0.05, 0.3),
                      random.Uniform(0.03, 0.08), random.Uniform(0.005, 0.02)};
    // Timing: progress u(i) integrates a positive, smoothly varying speed.
    const SmoothNoise speed(random, 0.3);
    std::vector<double> u(frames, 0.0);
    for (int i = 1; i < frames; ++i) {
      const double s = static_cast<double>(i) / (frames - 1);
      u[i] = u[i - 1] + std::max(0.2, 1.0 + speed(s));
    }
    for (double& v : u) v /= u.back();
    // Flaws: stretches where the proxy leaves the path and wobbles.
    const int flaws = 1 + static_cast<int>(random.Uniform() < 0.5);
    std::vector<std::pair<double, double>> flaw_ranges;
    for (int f = 0; f < flaws; ++f) {
      const double start = random.Uniform(0.02, 0.9);
      flaw_ranges.emplace_back(start, start + random.Uniform(0.02, 0.07));
    }
    const Eigen::Vector3d flaw_offset(random.Uniform(-0.08, 0.08), random.Uniform(-0.08, 0.08), 0);
    const SmoothNoise taste(random, 1.5);
    const double liking = random.Uniform(-1.0, 2.5);

    Trajectory take;
    std::vector<double> quality(frames);
    for (int i = 0; i < frames; ++i) {
      Rigid3 pose = StoryPose(u[i], style);
      double flaw = 0.0;  // 0 outside a flaw, up to 1 in its middle
      for (const auto& [a, b] : flaw_ranges) {
        if (u[i] > a && u[i] < b) flaw = std::max(flaw, std::sin(M_PI * (u[i] - a) / (b - a)));
      }
      pose.translation += flaw * flaw_offset;
      pose.rotation =
          pose.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(0.4 * flaw * std::sin(0.5 * i),
                                                               Eigen::Vector3d::UnitY()));
      pose.translation += options.position_noise *
                          Eigen::Vector3d(random.Normal(), random.Normal(), random.Normal());
      const Eigen::Vector3d axis(random.Normal(), random.Normal(), random.Normal());
      pose.rotation =
          (pose.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(
                               options.rotation_noise * axis.norm(), axis.normalized())))
              .normalized();
      take.timestamps.push_back(i * period);
      take.poses.push_back(pose);
      quality[i] = liking + taste(u[i]) - 7.0 * flaw;
    }
    // The annotator: judgement of frame i is recorded at frame i + shift, with noise.
    Annotation annotation;
    double smoothed = quality[0];
    for (int i = 0; i < frames; ++i) {
      const int judged = std::max(0, i - shift);
      smoothed += 0.2 * (quality[judged] - smoothed);
      annotation.timestamps.push_back(i * period);
      annotation.values.push_back(std::clamp(smoothed + 0.3 * random.Normal(), -5.0, 5.0));
    }
    set.takes.push_back(std::move(take));
    set.annotations.push_back(std::move(annotation));
  }
  return set;
}

}  // namespace mmh::synthetic
