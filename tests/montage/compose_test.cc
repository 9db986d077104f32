// End-to-end tests of the compositor (paper, "Compositing the takes into the montage") and of
// layered objects and spatial markers, with independent oracles for every stage.
#include "montage/compose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/error.h"
#include "core/rigid3.h"
#include "montage/layered.h"
#include "tests/montage/oracles.h"

namespace mmh::montage {
namespace {

using oracle::NearRel;

constexpr double kPi = 3.14159265358979323846;

// The story: a smooth closed-ish 3D path with a rotating proxy.
Rigid3 StoryPose(double s) {
  Rigid3 p;
  p.translation =
      Eigen::Vector3d(0.3 * std::cos(2 * kPi * s), 0.2 * std::sin(4 * kPi * s), 1.0 + 0.05 * s);
  p.rotation =
      (Eigen::Quaterniond(Eigen::AngleAxisd(1.6 * kPi * s, Eigen::Vector3d::UnitZ())) *
       Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * std::sin(2 * kPi * s), Eigen::Vector3d::UnitX())))
          .normalized();
  return p;
}

Trajectory TakeOfStory(std::mt19937_64& rng, int frames, double amplitude, double phase,
                       double noise_m = 0.003, double noise_rad = 0.01) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Rigid3> poses;
  for (int j = 0; j < frames; ++j) {
    const double u = double(j) / double(frames - 1);
    Rigid3 p = StoryPose(oracle::Distort(u, amplitude, phase));
    p.translation += noise_m * Eigen::Vector3d(g(rng), g(rng), g(rng));
    const Eigen::Vector3d e = noise_rad * Eigen::Vector3d(g(rng), g(rng), g(rng));
    p.rotation =
        (p.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(e.norm(), e.normalized()))).normalized();
    poses.push_back(p);
  }
  return oracle::MakeTrajectory(poses, 1.0 / 30.0, 12.5);
}

Annotation PiecewiseAnnotation(std::mt19937_64& rng, const Trajectory& take) {
  Annotation a;
  a.timestamps = take.timestamps;
  std::uniform_real_distribution<double> level(-5.0, 5.0);
  std::uniform_int_distribution<int> piece(30, 120);
  std::normal_distribution<double> noise(0.0, 0.3);
  while (a.values.size() < take.size()) {
    const int len = piece(rng);
    const double v = level(rng);
    for (int i = 0; i < len && a.values.size() < take.size(); ++i) {
      a.values.push_back(std::clamp(v + noise(rng), -5.0, 5.0));
    }
  }
  return a;
}

Annotation ConstantAnnotation(const Trajectory& take, double value) {
  Annotation a;
  a.timestamps = take.timestamps;
  a.values.assign(take.size(), value);
  return a;
}

struct Scenario {
  std::vector<Trajectory> takes;
  std::vector<Annotation> annotations;
};

Scenario MakeScenario(std::mt19937_64& rng, int m, int min_len = 260, int max_len = 340) {
  Scenario s;
  std::uniform_int_distribution<int> len(min_len, max_len);
  std::uniform_real_distribution<double> amp(-0.5, 0.5), phase(0.0, 2 * kPi);
  for (int l = 0; l < m; ++l) {
    s.takes.push_back(TakeOfStory(rng, len(rng), amp(rng), phase(rng)));
    s.annotations.push_back(PiecewiseAnnotation(rng, s.takes.back()));
  }
  return s;
}

bool SameRotation(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double tol) {
  return (a.coeffs() - b.coeffs()).norm() <= tol || (a.coeffs() + b.coeffs()).norm() <= tol;
}

bool SamePose(const Rigid3& a, const Rigid3& b, double tol) {
  return SameRotation(a.rotation, b.rotation, tol) && (a.translation - b.translation).norm() <= tol;
}

// Every property of a montage that follows from the paper and the headers, with independent
// oracles for the warped annotations, the costs and the optimum.
void CheckMontage(const std::vector<Trajectory>& takes, const std::vector<Annotation>& annotations,
                  const ComposeOptions& options, const Montage& montage) {
  const int m = int(takes.size());
  const int ref = options.reference_take;
  const int n = int(takes[ref].size());
  const int d = options.labelling.min_segment_length;
  const int shift = 9;  // 0.3 s at 30 fps

  // Warps.
  ASSERT_EQ(int(montage.warps.size()), m);
  for (int l = 0; l < m; ++l) {
    ASSERT_EQ(int(montage.warps[l].size()), n) << "take " << l;
    const int N = int(takes[l].size());
    EXPECT_EQ(montage.warps[l].front(), 0);
    EXPECT_EQ(montage.warps[l].back(), N - 1);
    for (int t = 1; t < n; ++t) ASSERT_GE(montage.warps[l][t], montage.warps[l][t - 1]);
    if (l == ref || !options.time_warp) {
      for (int t = 0; t < n; ++t) ASSERT_EQ(montage.warps[l][t], t) << "take " << l;
    }
  }

  // Warped annotations: reaction shift, then eq. 6 (sum-conserving form).
  ASSERT_EQ(int(montage.warped_annotations.size()), m);
  for (int l = 0; l < m; ++l) {
    const auto shifted = oracle::MyShift(annotations[l].values, shift);
    const auto want = oracle::MyConservingWarp(shifted, montage.warps[l]);
    ASSERT_EQ(montage.warped_annotations[l].size(), want.size());
    double sum_want = 0, sum_got = 0, abs_sum = 0;
    for (int t = 0; t < n; ++t) {
      EXPECT_NEAR(montage.warped_annotations[l][t], want[t], 1e-9) << "take " << l << " t=" << t;
      sum_got += montage.warped_annotations[l][t];
    }
    for (double v : shifted) sum_want += v, abs_sum += std::abs(v);
    EXPECT_LE(std::abs(sum_got - sum_want), 1e-12 * std::max(1.0, abs_sum)) << "take " << l;
  }

  // Labels and segments.
  ASSERT_EQ(int(montage.labels.size()), n);
  const auto& segs = montage.segments;
  ASSERT_FALSE(segs.empty());
  int montage_frames = 0;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const MontageSegment& s = segs[i];
    SCOPED_TRACE("segment " + std::to_string(i));
    ASSERT_TRUE(s.take >= 0 && s.take < m);
    EXPECT_EQ(s.reference_first, i == 0 ? 0 : segs[i - 1].reference_last + 1);
    EXPECT_GT(s.reference_last - s.reference_first + 1, d) << "segment not longer than d";
    if (i > 0) {
      EXPECT_NE(s.take, segs[i - 1].take);
    }
    for (int t = s.reference_first; t <= s.reference_last; ++t) {
      ASSERT_EQ(montage.labels[t], s.take) << "t=" << t;
    }
    EXPECT_EQ(s.source_first, montage.warps[s.take][s.reference_first]);
    EXPECT_EQ(s.source_last, montage.warps[s.take][s.reference_last]);
    EXPECT_LE(s.source_first, s.source_last);
    EXPECT_EQ(s.montage_first, montage_frames);
    EXPECT_EQ(s.montage_last - s.montage_first, s.source_last - s.source_first);
    montage_frames += s.source_last - s.source_first + 1;
  }
  EXPECT_EQ(segs.back().reference_last, n - 1);
  EXPECT_EQ(int(montage.trajectory.size()), montage_frames);
  EXPECT_EQ(montage.trajectory.timestamps.size(), montage.trajectory.poses.size());
  EXPECT_EQ(montage.summary.montage_frames, montage_frames);

  // Timestamps strictly increasing, at the takes' frame period.
  for (std::size_t f = 1; f < montage.trajectory.timestamps.size(); ++f) {
    ASSERT_GT(montage.trajectory.timestamps[f], montage.trajectory.timestamps[f - 1]);
    EXPECT_NEAR(montage.trajectory.timestamps[f] - montage.trajectory.timestamps[f - 1], 1.0 / 30.0,
                1e-6);
  }

  // Poses farther than the half window (7) from every transition are the takes' own poses.
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const MontageSegment& s = segs[i];
    const int lo = i == 0 ? s.montage_first : s.montage_first + 8;
    const int hi = i + 1 == segs.size() ? s.montage_last : s.montage_last - 7;
    for (int f = lo; f <= hi; ++f) {
      const Rigid3& want = takes[s.take].poses[s.source_first + (f - s.montage_first)];
      ASSERT_TRUE(SamePose(montage.trajectory.poses[f], want, 1e-12))
          << "montage frame " << f << " should be take " << s.take << " frame "
          << s.source_first + (f - s.montage_first);
    }
  }

  // Blending (header of BlendMontage, linear weights, W = 15) where no narrowing can apply: both
  // neighbouring segments at least W montage frames long.
  if (options.blend.window == 15 && options.blend.weight == BlendWeight::kLinear) {
    for (std::size_t i = 1; i < segs.size(); ++i) {
      const MontageSegment& out = segs[i - 1];
      const MontageSegment& in = segs[i];
      if (out.montage_last - out.montage_first + 1 < 15) continue;
      if (in.montage_last - in.montage_first + 1 < 15) continue;
      const int c = in.montage_first;
      for (int f = c - 7; f <= c + 7; ++f) {
        const int N_out = int(takes[out.take].size()), N_in = int(takes[in.take].size());
        const int j_out = std::clamp(out.source_last + (f - out.montage_last), 0, N_out - 1);
        const int j_in = std::clamp(in.source_first + (f - in.montage_first), 0, N_in - 1);
        const double w = double(f - c + 8) / 16.0;
        const Rigid3 want =
            Interpolate(takes[out.take].poses[j_out], takes[in.take].poses[j_in], w);
        EXPECT_TRUE(SamePose(montage.trajectory.poses[f], want, 1e-9))
            << "blend at transition into montage frame " << c << ", frame " << f;
      }
    }
  }

  // Summary and the optimum, from independent costs: C_d = -a' (eq. 8), C_s of eq. 9 (scaled
  // mean, lambda 0.8, W = [-7, 7]) computed here.
  const ComposeSummary& sum = montage.summary;
  EXPECT_EQ(sum.takes, m);
  EXPECT_EQ(sum.reference_frames, n);
  EXPECT_EQ(sum.reaction_shift_frames, shift);
  EXPECT_TRUE(NearRel(sum.data_cost + sum.smoothness_cost, sum.total_cost))
      << sum.data_cost << " + " << sum.smoothness_cost << " vs " << sum.total_cost;
  EXPECT_LE(sum.unconstrained_cost,
            sum.total_cost + 1e-9 * std::max(1.0, std::abs(sum.total_cost)));
  EXPECT_LE(sum.unconstrained_short_segments, sum.unconstrained_segments);
  int shortest_ref = std::numeric_limits<int>::max(), shortest_montage = shortest_ref;
  for (const auto& s : segs) {
    shortest_ref = std::min(shortest_ref, s.reference_last - s.reference_first + 1);
    shortest_montage = std::min(shortest_montage, s.montage_last - s.montage_first + 1);
  }
  EXPECT_EQ(sum.shortest_segment_reference, shortest_ref);
  EXPECT_EQ(sum.shortest_segment_montage, shortest_montage);
  if (sum.unconstrained_cost != 0) {
    EXPECT_NEAR(
        sum.constraint_increase_percent,
        100.0 * (sum.total_cost - sum.unconstrained_cost) / std::abs(sum.unconstrained_cost),
        1e-9 * std::max(1.0, std::abs(sum.constraint_increase_percent)));
  }

  if (options.time_warp) {
    ASSERT_EQ(int(sum.dtw_costs.size()), m);
    for (int l = 0; l < m; ++l) {
      if (l == ref) {
        EXPECT_EQ(sum.dtw_costs[l], 0.0);
        continue;
      }
      const double lambda = options.dtw.lambda;
      switch (options.dtw.step_pattern) {
        case StepPattern::kLiteral:
        case StepPattern::kSlopeLimited: {
          const int max_step = options.dtw.step_pattern == StepPattern::kLiteral ? -1 : 2;
          EXPECT_TRUE(NearRel(sum.dtw_costs[l],
                              oracle::MyWarpCost(takes[ref], takes[l], montage.warps[l], lambda)))
              << "take " << l;
          EXPECT_TRUE(
              NearRel(sum.dtw_costs[l], oracle::DtwWarpDp(takes[ref], takes[l], lambda, max_step)))
              << "take " << l << " warp is not the eq. 4 optimum";
          break;
        }
        case StepPattern::kSymmetric:
          EXPECT_TRUE(
              NearRel(sum.dtw_costs[l], oracle::DtwSymmetricDp(takes[ref], takes[l], lambda)))
              << "take " << l;
          break;
      }
    }
  }

  oracle::Problem p;
  p.n = n;
  p.m = m;
  p.data.resize(std::size_t(n) * m);
  for (int t = 0; t < n; ++t)
    for (int l = 0; l < m; ++l) {
      const auto want =
          oracle::MyConservingWarp(oracle::MyShift(annotations[l].values, shift), montage.warps[l]);
      p.data[std::size_t(t) * m + l] = -want[t];
    }
  p.trans.assign(std::size_t(n - 1) * m * m, 0.0);
  for (int t = 0; t + 1 < n; ++t)
    for (int l = 0; l < m; ++l)
      for (int k = 0; k < m; ++k)
        if (l != k)
          p.trans[(std::size_t(t) * m + l) * m + k] = oracle::MySmoothness(
              takes[l], montage.warps[l], takes[k], montage.warps[k], t, 0.8, 7, true);
  const double mu = options.labelling.mu;
  const oracle::Eval e = oracle::Evaluate(p, montage.labels, mu);
  EXPECT_TRUE(NearRel(e.total, sum.total_cost)) << e.total << " vs " << sum.total_cost;
  EXPECT_TRUE(NearRel(e.data, sum.data_cost)) << e.data << " vs " << sum.data_cost;
  EXPECT_TRUE(NearRel(e.smooth, sum.smoothness_cost)) << e.smooth << " vs " << sum.smoothness_cost;
  const double optimum = oracle::SemiMarkovOptimum(p, mu, d);
  EXPECT_TRUE(NearRel(optimum, sum.total_cost))
      << "constrained optimum " << optimum << " vs " << sum.total_cost;
  const double optimum0 = oracle::SemiMarkovOptimum(p, mu, 0);
  EXPECT_TRUE(NearRel(optimum0, sum.unconstrained_cost))
      << "unconstrained optimum " << optimum0 << " vs " << sum.unconstrained_cost;
}

TEST(Compose, EndToEndInvariantsAndOptimum) {
  std::mt19937_64 rng(2014);
  int multi_segment = 0, blended_checked = 0;
  for (int rep = 0; rep < 8; ++rep) {
    const int m = 2 + rep % 3;
    const Scenario s = MakeScenario(rng, m);
    ComposeOptions options;
    if (rep == 5) options.reference_take = 1;
    if (rep == 6) options.labelling.mu = 10.0;
    if (rep == 7) options.labelling.min_segment_length = 30;
    SCOPED_TRACE("rep " + std::to_string(rep) + " m=" + std::to_string(m));
    const Montage montage = Compose(s.takes, s.annotations, options);
    CheckMontage(s.takes, s.annotations, options, montage);
    if (montage.segments.size() > 1) ++multi_segment;
    for (std::size_t i = 1; i < montage.segments.size(); ++i) {
      const auto& a = montage.segments[i - 1];
      const auto& b = montage.segments[i];
      blended_checked +=
          a.montage_last - a.montage_first >= 14 && b.montage_last - b.montage_first >= 14;
    }
    if (HasFailure()) return;
  }
  EXPECT_GE(multi_segment, 4) << "scenarios should produce transitions";
  EXPECT_GE(blended_checked, 3);
}

// The other DTW step patterns go through the same pipeline; every invariant still holds (a valid
// warp with both ends fixed, the conserved annotation sum, contiguous segments covering the takes).
TEST(Compose, OtherStepPatterns) {
  for (StepPattern pattern : {StepPattern::kSlopeLimited, StepPattern::kSymmetric}) {
    std::mt19937_64 rng(404);
    // Lengths within a factor of 2 of each other so that the slope-limited warp exists.
    const Scenario s = MakeScenario(rng, 3, 280, 330);
    ComposeOptions options;
    options.dtw.step_pattern = pattern;
    SCOPED_TRACE(pattern == StepPattern::kSymmetric ? "symmetric" : "slope-limited");
    Montage montage;
    try {
      montage = Compose(s.takes, s.annotations, options);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "Compose threw on valid input: " << e.what();
      continue;
    }
    CheckMontage(s.takes, s.annotations, options, montage);
    for (std::size_t l = 0; l < s.takes.size(); ++l) {
      EXPECT_TRUE(IsValidWarp(montage.warps[l], int(s.takes[l].size()), pattern)) << "take " << l;
    }
  }
}

TEST(Compose, QuaternionSignsDoNotMatter) {
  std::mt19937_64 rng(77);
  const Scenario s = MakeScenario(rng, 3);
  Scenario flipped = s;
  for (auto& take : flipped.takes) take = oracle::FlipSigns(take, rng);
  const ComposeOptions options;
  const Montage a = Compose(s.takes, s.annotations, options);
  const Montage b = Compose(flipped.takes, flipped.annotations, options);
  EXPECT_EQ(a.labels, b.labels);
  EXPECT_EQ(a.warps, b.warps);
  ASSERT_EQ(a.segments.size(), b.segments.size());
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    EXPECT_EQ(a.segments[i].take, b.segments[i].take);
    EXPECT_EQ(a.segments[i].reference_first, b.segments[i].reference_first);
    EXPECT_EQ(a.segments[i].reference_last, b.segments[i].reference_last);
    EXPECT_EQ(a.segments[i].source_first, b.segments[i].source_first);
    EXPECT_EQ(a.segments[i].source_last, b.segments[i].source_last);
    EXPECT_EQ(a.segments[i].montage_first, b.segments[i].montage_first);
    EXPECT_EQ(a.segments[i].montage_last, b.segments[i].montage_last);
  }
  EXPECT_EQ(a.summary.total_cost, b.summary.total_cost);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  for (std::size_t f = 0; f < a.trajectory.size(); ++f) {
    EXPECT_TRUE(SamePose(a.trajectory.poses[f], b.trajectory.poses[f], 1e-9)) << "frame " << f;
  }
  CheckMontage(flipped.takes, flipped.annotations, options, b);
}

TEST(Compose, LikedTakeAloneIsTheMontage) {
  std::mt19937_64 rng(5);
  for (int liked : {0, 1, 2}) {
    Scenario s = MakeScenario(rng, 3);
    for (int l = 0; l < 3; ++l)
      s.annotations[l] = ConstantAnnotation(s.takes[l], l == liked ? 5.0 : -5.0);
    const ComposeOptions options;
    const Montage montage = Compose(s.takes, s.annotations, options);
    SCOPED_TRACE("liked take " + std::to_string(liked));
    const int N = int(s.takes[liked].size());
    ASSERT_EQ(montage.segments.size(), 1u);
    const MontageSegment& seg = montage.segments[0];
    EXPECT_EQ(seg.take, liked);
    EXPECT_EQ(seg.source_first, 0);
    EXPECT_EQ(seg.source_last, N - 1);
    EXPECT_EQ(seg.reference_first, 0);
    EXPECT_EQ(seg.reference_last, int(s.takes[0].size()) - 1);
    EXPECT_EQ(seg.montage_first, 0);
    EXPECT_EQ(seg.montage_last, N - 1);
    ASSERT_EQ(int(montage.trajectory.size()), N);
    for (int f = 0; f < N; ++f) {
      EXPECT_TRUE(SamePose(montage.trajectory.poses[f], s.takes[liked].poses[f], 1e-12))
          << "frame " << f;
    }
    for (int l : montage.labels) EXPECT_EQ(l, liked);
    EXPECT_NEAR(montage.summary.smoothness_cost, 0.0, 1e-9);
    CheckMontage(s.takes, s.annotations, options, montage);
  }
}

TEST(Compose, BadInputThrows) {
  std::mt19937_64 rng(6);
  const Scenario s = MakeScenario(rng, 3);
  const ComposeOptions options;
  EXPECT_NO_THROW(Compose(s.takes, s.annotations, options));

  // One take only.
  EXPECT_THROW(Compose({s.takes[0]}, {s.annotations[0]}, options), mmh::InputError);
  // No takes.
  EXPECT_THROW(Compose({}, {}, options), mmh::InputError);
  // Fewer annotations than takes.
  EXPECT_THROW(Compose(s.takes, {s.annotations[0], s.annotations[1]}, options), mmh::InputError);
  {  // Annotation length mismatch.
    Scenario b = s;
    b.annotations[1].values.pop_back();
    b.annotations[1].timestamps.pop_back();
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
  }
  {  // A take not longer than d = 60.
    Scenario b = s;
    b.takes[2] = TakeOfStory(rng, 50, 0.1, 0.2);
    b.annotations[2] = PiecewiseAnnotation(rng, b.takes[2]);
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
    b.takes[2] = TakeOfStory(rng, 60, 0.1, 0.2);
    b.annotations[2] = PiecewiseAnnotation(rng, b.takes[2]);
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
    ComposeOptions d0 = options;
    d0.labelling.min_segment_length = 0;  // "unless d = 0"
    EXPECT_NO_THROW(Compose(b.takes, b.annotations, d0));
  }
  {  // NaN in a pose.
    Scenario b = s;
    b.takes[1].poses[10].translation.x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
    b = s;
    b.takes[0].poses[3].rotation.w() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
  }
  {  // NaN or out-of-range annotation values.
    Scenario b = s;
    b.annotations[2].values[5] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
    b = s;
    b.annotations[2].values[5] = 7.0;
    EXPECT_THROW(Compose(b.takes, b.annotations, options), mmh::InputError);
  }
}

// ------------------------------------------------------------------------------------------------
// Layered objects.

TEST(Layered, SecondObjectWithoutWarping) {
  std::mt19937_64 rng(8);
  LayeredObject first;
  first.name = "mario";
  {
    const Scenario s = MakeScenario(rng, 3);
    first.takes = s.takes;
    first.annotations = s.annotations;
  }
  LayeredObject second;
  second.name = "monster";
  const int L = 280;
  for (int l = 0; l < 3; ++l) {
    second.takes.push_back(TakeOfStory(rng, L, 0.0, 0.0, 0.01, 0.03));
    second.annotations.push_back(PiecewiseAnnotation(rng, second.takes.back()));
  }
  const ComposeOptions options;
  const std::vector<Montage> montages = ComposeLayered({first, second}, options);
  ASSERT_EQ(montages.size(), 2u);

  const Montage alone = Compose(first.takes, first.annotations, options);
  EXPECT_EQ(montages[0].labels, alone.labels);
  EXPECT_EQ(montages[0].warps, alone.warps);
  CheckMontage(first.takes, first.annotations, options, montages[0]);

  ComposeOptions unwarped = options;
  unwarped.time_warp = false;
  CheckMontage(second.takes, second.annotations, unwarped, montages[1]);
  EXPECT_EQ(int(montages[1].trajectory.size()), L);  // identity warps: no change of length
  const Montage second_alone = Compose(second.takes, second.annotations, unwarped);
  EXPECT_EQ(montages[1].labels, second_alone.labels);
}

TEST(Layered, UnequalLengthsOfLaterObjectThrow) {
  std::mt19937_64 rng(9);
  LayeredObject first, second;
  first.name = "a";
  second.name = "b";
  const Scenario s = MakeScenario(rng, 2);
  first.takes = s.takes;
  first.annotations = s.annotations;
  for (int len : {200, 205}) {
    second.takes.push_back(TakeOfStory(rng, len, 0.0, 0.0));
    second.annotations.push_back(PiecewiseAnnotation(rng, second.takes.back()));
  }
  EXPECT_THROW(ComposeLayered({first, second}, ComposeOptions()), mmh::InputError);
}

TEST(Layered, SpatialMarkers) {
  SpatialMarkers markers;  // 60 frames
  markers.Add("monster", 100);
  EXPECT_THROW(markers.Add("monster", 159), mmh::InputError);  // within 60 frames
  EXPECT_THROW(markers.Add("monster", 41), mmh::InputError);
  EXPECT_THROW(markers.Add("monster", 100), mmh::InputError);
  EXPECT_NO_THROW(markers.Add("monster", 160));  // exactly 60 apart
  EXPECT_NO_THROW(markers.Add("monster", 40));
  EXPECT_NO_THROW(markers.Add("mario", 100));  // another object
  EXPECT_THROW(markers.Add("mario", -1), mmh::InputError);
  EXPECT_THROW(markers.Add("mario", 130), mmh::InputError);

  std::vector<SpatialMarker> all = markers.All();
  ASSERT_EQ(all.size(), 4u);
  // Ordered by object then frame.
  EXPECT_EQ(all[0].object, "mario");
  EXPECT_EQ(all[0].frame, 100);
  EXPECT_EQ(all[1].object, "monster");
  EXPECT_EQ(all[1].frame, 40);
  EXPECT_EQ(all[2].frame, 100);
  EXPECT_EQ(all[3].frame, 160);

  EXPECT_FALSE(markers.Remove("monster", 130));
  EXPECT_FALSE(markers.Remove("nobody", 100));
  EXPECT_TRUE(markers.Remove("monster", 100));
  EXPECT_FALSE(markers.Remove("monster", 100));
  EXPECT_EQ(markers.All().size(), 3u);
  // The slot is free again: 100 is 60 from 40 and 160.
  EXPECT_NO_THROW(markers.Add("monster", 100));
  EXPECT_TRUE(markers.Remove("monster", 100));

  // Poses: the object's montage pose at the marker's frame.
  std::mt19937_64 rng(10);
  std::map<std::string, Trajectory> montages;
  montages["monster"] = oracle::RandomTrajectory(rng, 200);
  montages["mario"] = oracle::RandomTrajectory(rng, 150);
  const std::vector<Rigid3> poses = markers.Poses(montages);
  all = markers.All();
  ASSERT_EQ(poses.size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Rigid3& want = montages.at(all[i].object).poses[all[i].frame];
    EXPECT_TRUE(SamePose(poses[i], want, 0.0)) << "marker " << i;
  }
  // Unknown object, or a frame past the montage's end.
  std::map<std::string, Trajectory> missing = {{"monster", montages["monster"]}};
  EXPECT_THROW(markers.Poses(missing), mmh::InputError);
  std::map<std::string, Trajectory> short_montages = montages;
  short_montages["monster"] = oracle::RandomTrajectory(rng, 160);  // frame 160 is past the end
  EXPECT_THROW(markers.Poses(short_montages), mmh::InputError);

  // Another spacing.
  SpatialMarkers close(10);
  close.Add("x", 0);
  EXPECT_THROW(close.Add("x", 9), mmh::InputError);
  EXPECT_NO_THROW(close.Add("x", 10));
}

}  // namespace
}  // namespace mmh::montage
