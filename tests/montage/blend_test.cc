// Oracle tests of unwarping (paper, "Unwarping the Montage") and blending ("Motion Blending"),
// from the contracts in blend.h.
#include "montage/blend.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/rigid3.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

bool SamePose(const Rigid3& a, const Rigid3& b, double tol) {
  const bool rot = (a.rotation.coeffs() - b.rotation.coeffs()).norm() <= tol ||
                   (a.rotation.coeffs() + b.rotation.coeffs()).norm() <= tol;
  return rot && (a.translation - b.translation).norm() <= tol;
}

struct Case {
  std::vector<Trajectory> takes;
  std::vector<std::vector<int>> warps;
  std::vector<int> labels;
};

Case RandomCase(std::mt19937_64& rng, int min_run, int max_run) {
  Case c;
  const int m = 3;
  const int n = std::uniform_int_distribution<int>(120, 260)(rng);
  const oracle::RandomWalkPath path(rng, 300);
  for (int l = 0; l < m; ++l) {
    const int N = l == 0 ? n : std::uniform_int_distribution<int>(n / 2 + 2, 2 * n)(rng);
    c.takes.push_back(oracle::FlipSigns(
        oracle::SampleTake(path, N, 0.3 * l - 0.3, 0.5 * l, 0.003, 0.02, rng), rng, 0.2));
    if (l == 0) {
      std::vector<int> id(n);
      std::iota(id.begin(), id.end(), 0);
      c.warps.push_back(id);
    } else {
      c.warps.push_back(oracle::RandomMonotoneWarp(rng, n, N));
    }
  }
  std::uniform_int_distribution<int> run(min_run, max_run);
  int label = int(rng() % m);
  while (int(c.labels.size()) < n) {
    const int len = run(rng);
    for (int i = 0; i < len && int(c.labels.size()) < n; ++i) c.labels.push_back(label);
    label = (label + 1 + int(rng() % (m - 1))) % m;
  }
  return c;
}

// The unwarped montage played frame by frame, without Unwarp's per-segment formula: walking the
// reference timeline, the first frame of a run of take l plays that take's source frame w_l(t);
// each further step t - 1 -> t inside the run plays the source frames after w_l(t - 1) up to
// w_l(t), each once, in order (the paper's "corresponding interval" of the original take, built
// step by step). Returns the (take, source frame) of every montage frame, and the reference frame
// each montage frame was played from.
struct Played {
  std::vector<std::pair<int, int>> frames;
  std::vector<int> reference;
};
Played PlayUnwarped(const std::vector<int>& labels, const std::vector<std::vector<int>>& warps) {
  Played played;
  for (int t = 0; t < static_cast<int>(labels.size()); ++t) {
    const int l = labels[t];
    const int from = t > 0 && labels[t - 1] == l ? warps[l][t - 1] + 1 : warps[l][t];
    for (int source = from; source <= warps[l][t]; ++source) {
      played.frames.emplace_back(l, source);
      played.reference.push_back(t);
    }
  }
  return played;
}

TEST(Blend, UnwarpPlaysEveryRunsSourceFramesOnce) {
  std::mt19937_64 rng(31);
  for (int rep = 0; rep < 40; ++rep) {
    SCOPED_TRACE("rep " + std::to_string(rep));
    const Case c = RandomCase(rng, 1, 50);
    const auto segments = Unwarp(c.labels, c.warps);
    const Played want = PlayUnwarped(c.labels, c.warps);
    // The segments' montage frames, expanded: contiguous from 0, each a take's source frame.
    std::vector<std::pair<int, int>> got;
    int next_montage = 0, next_reference = 0;
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const MontageSegment& s = segments[i];
      SCOPED_TRACE("segment " + std::to_string(i));
      ASSERT_EQ(s.montage_first, next_montage);
      ASSERT_EQ(s.montage_last - s.montage_first, s.source_last - s.source_first);
      for (int f = s.source_first; f <= s.source_last; ++f) got.emplace_back(s.take, f);
      // The segment starts where its first montage frame was played from and covers exactly one
      // run of equal labels (maximal: the neighbours' takes differ; the runs tile the timeline).
      ASSERT_EQ(s.reference_first, next_reference);
      ASSERT_LT(s.montage_first, static_cast<int>(want.reference.size()));
      EXPECT_EQ(want.reference[s.montage_first], s.reference_first);
      for (int t = s.reference_first; t <= s.reference_last; ++t) ASSERT_EQ(c.labels[t], s.take);
      if (i > 0) EXPECT_NE(segments[i - 1].take, s.take);
      next_montage = s.montage_last + 1;
      next_reference = s.reference_last + 1;
    }
    EXPECT_EQ(next_reference, static_cast<int>(c.labels.size()));
    ASSERT_EQ(got, want.frames);
    if (HasFailure()) return;
  }
}

// A run of one reference frame plays one source frame; a flat stretch of a warp (several
// reference frames on one source frame) plays it once.
TEST(Blend, UnwarpByHand) {
  // Take 0 is the reference (identity warp); take 1 runs at half speed, then holds.
  const std::vector<std::vector<int>> warps = {{0, 1, 2, 3, 4, 5}, {0, 2, 4, 6, 6, 6}};
  const auto segments = Unwarp({0, 1, 1, 0, 1, 1}, warps);
  ASSERT_EQ(segments.size(), 4u);
  auto expect = [&](int i, int take, int r0, int r1, int s0, int s1, int m0, int m1) {
    SCOPED_TRACE(i);
    EXPECT_EQ(segments[i].take, take);
    EXPECT_EQ(segments[i].reference_first, r0);
    EXPECT_EQ(segments[i].reference_last, r1);
    EXPECT_EQ(segments[i].source_first, s0);
    EXPECT_EQ(segments[i].source_last, s1);
    EXPECT_EQ(segments[i].montage_first, m0);
    EXPECT_EQ(segments[i].montage_last, m1);
  };
  expect(0, 0, 0, 0, 0, 0, 0, 0);
  expect(1, 1, 1, 2, 2, 4, 1, 3);  // source 2, 3, 4 at the take's own speed
  expect(2, 0, 3, 3, 3, 3, 4, 4);
  expect(3, 1, 4, 5, 6, 6, 5, 5);  // the held frame once
}

void CheckBlend(const Case& c, const BlendOptions& options, const std::string& where) {
  SCOPED_TRACE(where);
  const auto segs = Unwarp(c.labels, c.warps);  // checked against PlayUnwarped above
  int narrowed = -1;
  const double start = 3.25, period = 1.0 / 30.0;
  const Trajectory montage = BlendMontage(c.takes, segs, options, start, period, &narrowed);
  const int frames = segs.back().montage_last + 1;
  ASSERT_EQ(int(montage.size()), frames);
  ASSERT_EQ(int(montage.timestamps.size()), frames);
  for (int f = 0; f < frames; ++f) {
    EXPECT_NEAR(montage.timestamps[f], start + f * period, 1e-9) << "frame " << f;
  }

  const int half = (options.window - 1) / 2;
  auto length = [](const MontageSegment& s) { return s.montage_last - s.montage_first + 1; };
  // Frames farther than the half window from every transition: the takes' own poses.
  std::vector<bool> near(frames, false);
  bool any_short = false;
  for (std::size_t i = 1; i < segs.size(); ++i) {
    const int t = segs[i].montage_first;
    for (int f = std::max(0, t - half); f <= std::min(frames - 1, t + half); ++f) near[f] = true;
    if (length(segs[i - 1]) < options.window || length(segs[i]) < options.window) any_short = true;
  }
  for (const auto& s : segs) {
    for (int f = s.montage_first; f <= s.montage_last; ++f) {
      if (near[f]) continue;
      const Rigid3& want = c.takes[s.take].poses[s.source_first + (f - s.montage_first)];
      ASSERT_TRUE(SamePose(montage.poses[f], want, 0.0)) << "unblended frame " << f;
    }
  }
  if (options.window > 1) {
    EXPECT_EQ(narrowed > 0, any_short) << "narrowed " << narrowed;
  }

  // Transitions whose neighbours are both at least a window long: the full window, with
  // w = (f - i + (W+1)/2) / (W+1) (smoothstep: 3w^2 - 2w^3), the outgoing take continued past
  // its segment and the incoming one before its segment, clamped at the takes' ends.
  // (W = 1 means no blending at all: every frame was checked as unblended above.)
  int full_windows = 0;
  for (std::size_t i = 1; i < segs.size() && options.window > 1; ++i) {
    const MontageSegment& out = segs[i - 1];
    const MontageSegment& in = segs[i];
    if (length(out) < options.window || length(in) < options.window) continue;
    ++full_windows;
    const int t = in.montage_first;
    for (int f = t - half; f <= t + half; ++f) {
      const int n_out = int(c.takes[out.take].size()), n_in = int(c.takes[in.take].size());
      const int j_out = std::clamp(out.source_last + (f - out.montage_last), 0, n_out - 1);
      const int j_in = std::clamp(in.source_first + (f - in.montage_first), 0, n_in - 1);
      double w = double(f - t + (options.window + 1) / 2) / double(options.window + 1);
      if (options.weight == BlendWeight::kSmoothstep) w = w * w * (3 - 2 * w);
      const Rigid3 want =
          Interpolate(c.takes[out.take].poses[j_out], c.takes[in.take].poses[j_in], w);
      EXPECT_TRUE(SamePose(montage.poses[f], want, 1e-9))
          << "transition into " << t << ", frame " << f << " (weight " << w << ")";
    }
  }
  if (options.window > 1 && segs.size() > 1) {
    EXPECT_GT(full_windows, 0);
  }
}

TEST(Blend, LinearWindow15) {
  std::mt19937_64 rng(32);
  for (int rep = 0; rep < 20; ++rep) {
    const Case c = RandomCase(rng, rep % 2 ? 20 : 3, 70);
    CheckBlend(c, BlendOptions(), "rep " + std::to_string(rep));
    if (HasFailure()) return;
  }
}

TEST(Blend, SmoothstepAndOtherWindows) {
  std::mt19937_64 rng(33);
  for (int rep = 0; rep < 20; ++rep) {
    const Case c = RandomCase(rng, rep % 2 ? 20 : 3, 70);
    BlendOptions o;
    o.weight = rep % 2 ? BlendWeight::kSmoothstep : BlendWeight::kLinear;
    o.window = 1 + 2 * int(rng() % 10);  // odd, 1 .. 19
    CheckBlend(c, o, "rep " + std::to_string(rep) + " window " + std::to_string(o.window));
    if (HasFailure()) return;
  }
}

TEST(Blend, WindowOneIsPlainConcatenation) {
  std::mt19937_64 rng(34);
  const Case c = RandomCase(rng, 3, 40);
  BlendOptions o;
  o.window = 1;
  const auto segs = Unwarp(c.labels, c.warps);
  const Trajectory montage = BlendMontage(c.takes, segs, o, 0.0, 0.04);
  int f = 0;
  for (const auto& s : segs) {
    for (int j = s.source_first; j <= s.source_last; ++j, ++f) {
      ASSERT_LT(f, int(montage.size()));
      EXPECT_TRUE(SamePose(montage.poses[f], c.takes[s.take].poses[j], 0.0)) << "frame " << f;
    }
  }
  EXPECT_EQ(f, int(montage.size()));
}

}  // namespace
}  // namespace mmh::montage
