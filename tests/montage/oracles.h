// Independent oracles for the montage tests, written from the paper (eqs. 1-12) and the headers'
// contracts, never from the implementation. Everything here is the simplest obviously-correct
// form: brute force, textbook dynamic programmes, direct sums.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/rigid3.h"
#include "core/trajectory.h"

namespace mmh::montage::oracle {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// |a - b| <= rel * max(1, |a|, |b|).
inline bool NearRel(double a, double b, double rel = 1e-9) {
  const double scale = std::max({1.0, std::abs(a), std::abs(b)});
  return std::abs(a - b) <= rel * scale;
}

// ---------------------------------------------------------------------------------------------
// Eq. 5 with the DESIGN.md sign rule: ||q1 - q2|| replaced by min(||q1 - q2||, ||q1 + q2||).
inline double Cmatch(const Rigid3& a, const Rigid3& b, double lambda) {
  const Eigen::Vector4d qa = a.rotation.coeffs();
  const Eigen::Vector4d qb = b.rotation.coeffs();
  const double rot = std::min((qa - qb).norm(), (qa + qb).norm());
  return rot + lambda * (a.translation - b.translation).norm();
}

// ---------------------------------------------------------------------------------------------
// Random geometry.
inline Eigen::Quaterniond RandomUnitQuaternion(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::Vector4d v;
  do {
    v = Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng));
  } while (v.norm() < 1e-3);
  v.normalize();
  return Eigen::Quaterniond(v[3], v[0], v[1], v[2]);  // (w, x, y, z)
}

inline Eigen::Quaterniond Negated(const Eigen::Quaterniond& q) {
  return Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z());
}

inline Trajectory MakeTrajectory(const std::vector<Rigid3>& poses, double period = 1.0 / 30.0,
                                 double start = 0.0) {
  Trajectory t;
  t.poses = poses;
  t.timestamps.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) t.timestamps[i] = start + period * double(i);
  return t;
}

// Independent random poses, quaternion sign random.
inline Trajectory RandomTrajectory(std::mt19937_64& rng, int frames) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Rigid3> poses;
  for (int i = 0; i < frames; ++i) {
    poses.emplace_back(RandomUnitQuaternion(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)));
  }
  return MakeTrajectory(poses);
}

// Flip the sign of every quaternion with probability p.
inline Trajectory FlipSigns(const Trajectory& in, std::mt19937_64& rng, double p = 0.5) {
  Trajectory out = in;
  std::bernoulli_distribution flip(p);
  for (auto& pose : out.poses) {
    if (flip(rng)) pose.rotation = Negated(pose.rotation);
  }
  return out;
}

// A "random walk" motion sampled at `knots` points; Sample(s) interpolates it for s in [0, 1]
// (lerp of translations, slerp of rotations).
struct RandomWalkPath {
  std::vector<Eigen::Vector3d> x;
  std::vector<Eigen::Quaterniond> q;

  RandomWalkPath(std::mt19937_64& rng, int knots, double step_m = 0.01, double step_rad = 0.04) {
    std::normal_distribution<double> g(0.0, 1.0);
    Eigen::Vector3d p(0, 0, 1);
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    Eigen::Quaterniond r = RandomUnitQuaternion(rng);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int i = 0; i < knots; ++i) {
      x.push_back(p);
      q.push_back(r);
      // Smoothed random walk (random velocity) so the path has shape.
      v = 0.8 * v + 0.2 * step_m * Eigen::Vector3d(g(rng), g(rng), g(rng));
      w = 0.8 * w + 0.2 * step_rad * Eigen::Vector3d(g(rng), g(rng), g(rng));
      p += v;
      const double angle = w.norm();
      if (angle > 0) r = (r * Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle))).normalized();
    }
  }

  Rigid3 Sample(double s) const {
    s = std::clamp(s, 0.0, 1.0);
    const double f = s * double(x.size() - 1);
    const int i = std::min(int(f), int(x.size()) - 2);
    const double a = f - i;
    Rigid3 out;
    out.translation = (1 - a) * x[i] + a * x[i + 1];
    out.rotation = q[i].slerp(a, q[i + 1]).normalized();
    return out;
  }
};

// Monotone time distortion f: [0,1] -> [0,1], f(0) = 0, f(1) = 1.
inline double Distort(double u, double amplitude, double phase) {
  // u + a (sin(2 pi u + phase) - sin(phase)) / (2 pi) - u a (sin(2 pi + phase) - sin(phase))/(2pi)
  // The second correction is 0, so f(1) = 1; f' = 1 + a cos(...) > 0 for |a| < 1.
  constexpr double kTwoPi = 6.283185307179586;
  return u + amplitude * (std::sin(kTwoPi * u + phase) - std::sin(phase)) / kTwoPi;
}

// Samples `frames` poses along the path through a time distortion, with noise.
inline Trajectory SampleTake(const RandomWalkPath& path, int frames, double amplitude, double phase,
                             double noise_m, double noise_rad, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Rigid3> poses;
  for (int j = 0; j < frames; ++j) {
    const double u = frames == 1 ? 0.0 : double(j) / double(frames - 1);
    Rigid3 p = path.Sample(Distort(u, amplitude, phase));
    p.translation += noise_m * Eigen::Vector3d(g(rng), g(rng), g(rng));
    const Eigen::Vector3d e = noise_rad * Eigen::Vector3d(g(rng), g(rng), g(rng));
    if (e.norm() > 0) {
      p.rotation =
          (p.rotation * Eigen::Quaterniond(Eigen::AngleAxisd(e.norm(), e / e.norm()))).normalized();
    }
    poses.push_back(p);
  }
  return MakeTrajectory(poses);
}

// ---------------------------------------------------------------------------------------------
// DTW oracles: textbook full dynamic programmes (0-based, both ends fixed).

inline std::vector<double> CostMatrix(const Trajectory& ref, const Trajectory& src, double lambda) {
  const int n = int(ref.size()), N = int(src.size());
  std::vector<double> c(std::size_t(n) * N);
  for (int t = 0; t < n; ++t)
    for (int j = 0; j < N; ++j)
      c[std::size_t(t) * N + j] = Cmatch(ref.poses[t], src.poses[j], lambda);
  return c;
}

// kLiteral: D(t, j) = C(t, j) + min_{j' <= j} D(t-1, j') (max_step < 0: unbounded, the minimum
// over j' <= j kept as a running prefix minimum). kSlopeLimited: max_step = 2 (j - j' in {0,1,2}).
inline double DtwWarpDp(const Trajectory& ref, const Trajectory& src, double lambda, int max_step) {
  const int n = int(ref.size()), N = int(src.size());
  const std::vector<double> c = CostMatrix(ref, src, lambda);
  std::vector<double> prev(N, kInf), cur(N, kInf);
  prev[0] = c[0];
  for (int t = 1; t < n; ++t) {
    double prefix_min = kInf;
    for (int j = 0; j < N; ++j) {
      double best;
      if (max_step < 0) {
        prefix_min = std::min(prefix_min, prev[j]);
        best = prefix_min;
      } else {
        best = kInf;
        for (int jp = std::max(0, j - max_step); jp <= j; ++jp) best = std::min(best, prev[jp]);
      }
      cur[j] = best + c[std::size_t(t) * N + j];
    }
    std::swap(prev, cur);
  }
  return prev[N - 1];
}

// kSymmetric: path of cells with steps (1,0), (0,1), (1,1), cost summed over every cell.
inline double DtwSymmetricDp(const Trajectory& ref, const Trajectory& src, double lambda) {
  const int n = int(ref.size()), N = int(src.size());
  const std::vector<double> c = CostMatrix(ref, src, lambda);
  std::vector<double> D(std::size_t(n) * N, kInf);
  for (int t = 0; t < n; ++t) {
    for (int j = 0; j < N; ++j) {
      double best = (t == 0 && j == 0) ? 0.0 : kInf;
      if (t > 0) best = std::min(best, D[std::size_t(t - 1) * N + j]);
      if (j > 0) best = std::min(best, D[std::size_t(t) * N + j - 1]);
      if (t > 0 && j > 0) best = std::min(best, D[std::size_t(t - 1) * N + j - 1]);
      D[std::size_t(t) * N + j] = best + c[std::size_t(t) * N + j];
    }
  }
  return D[std::size_t(n) * N - 1];
}

inline double MyWarpCost(const Trajectory& ref, const Trajectory& src, const std::vector<int>& w,
                         double lambda) {
  double s = 0;
  for (std::size_t t = 0; t < w.size(); ++t) s += Cmatch(ref.poses[t], src.poses[w[t]], lambda);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Eq. 9 directly: C_s(t, l, k) = sum_{h=-H..H} C_match(T_l(w_l(t)+h), T_k(w_k(t+1)+h-1)) over
// the pairs inside both takes; truncated sum, or sum * (2H+1) / valid.
inline double MySmoothness(const Trajectory& take_l, const std::vector<int>& warp_l,
                           const Trajectory& take_k, const std::vector<int>& warp_k, int t,
                           double lambda, int half_window, bool scaled_mean) {
  double sum = 0;
  int valid = 0;
  for (int h = -half_window; h <= half_window; ++h) {
    const int i = warp_l[t] + h;
    const int j = warp_k[t + 1] + h - 1;
    if (i < 0 || i >= int(take_l.size()) || j < 0 || j >= int(take_k.size())) continue;
    sum += Cmatch(take_l.poses[i], take_k.poses[j], lambda);
    ++valid;
  }
  if (!scaled_mean) return sum;
  if (valid == 0) return 0.0;
  return sum * double(2 * half_window + 1) / double(valid);
}

// ---------------------------------------------------------------------------------------------
// Labelling oracles. data[t*m + l], trans[(t*m + l)*m + k] for t < n-1.
struct Problem {
  int n = 0, m = 0;
  std::vector<double> data;
  std::vector<double> trans;
  double D(int t, int l) const { return data[std::size_t(t) * m + l]; }
  double S(int t, int l, int k) const { return trans[(std::size_t(t) * m + l) * m + k]; }
};

struct Eval {
  double data = 0, smooth = 0, total = 0;
};

// Eq. 7.
inline Eval Evaluate(const Problem& p, const std::vector<int>& labels, double mu) {
  Eval e;
  for (int t = 0; t < p.n; ++t) e.data += p.D(t, labels[t]);
  double s = 0;
  for (int t = 0; t + 1 < p.n; ++t) s += p.S(t, labels[t], labels[t + 1]);
  e.smooth = mu * s;
  e.total = e.data + e.smooth;
  return e;
}

struct Run {
  int label, first, last;
};

inline std::vector<Run> Runs(const std::vector<int>& labels) {
  std::vector<Run> runs;
  for (int t = 0; t < int(labels.size()); ++t) {
    if (t == 0 || labels[t] != labels[t - 1]) {
      runs.push_back({labels[t], t, t});
    } else {
      runs.back().last = t;
    }
  }
  return runs;
}

// Eq. 12: every maximal run is longer than d.
inline bool Feasible(const std::vector<int>& labels, int d) {
  for (const Run& r : Runs(labels))
    if (r.last - r.first + 1 <= d) return false;
  return true;
}

// Textbook semi-Markov DP, O(n^2 m^2): V(e, l) = best cost of frames [0, e] whose last segment
// has label l, ends at e and starts at s with e - s + 1 > d:
//   V(e, l) = min_s [ (s == 0 ? 0 : min_{k != l} V(s-1, k) + mu C_s(s-1, k, l)) + sum_{t=s}^{e}
//   C_d(t, l) ].
// Returns +inf when no labelling is feasible.
inline double SemiMarkovOptimum(const Problem& p, double mu, int d) {
  const int n = p.n, m = p.m;
  std::vector<double> V(std::size_t(n) * m, kInf);
  for (int e = 0; e < n; ++e) {
    for (int l = 0; l < m; ++l) {
      double best = kInf;
      double segment = 0;  // sum_{t=s}^{e} C_d(t, l), grown as s moves left
      for (int s = e; s >= 0; --s) {
        segment += p.D(s, l);
        if (e - s + 1 <= d) continue;  // segment too short
        double before;
        if (s == 0) {
          before = 0;
        } else {
          before = kInf;
          for (int k = 0; k < m; ++k) {
            if (k == l) continue;
            const double v = V[std::size_t(s - 1) * m + k];
            if (v == kInf) continue;
            before = std::min(before, v + mu * p.S(s - 1, k, l));
          }
        }
        if (before == kInf) continue;
        best = std::min(best, before + segment);
      }
      V[std::size_t(e) * m + l] = best;
    }
  }
  double best = kInf;
  for (int l = 0; l < m; ++l) best = std::min(best, V[std::size_t(n - 1) * m + l]);
  return best;
}

// ---------------------------------------------------------------------------------------------
// Annotation oracles.

// A random valid warp [0, n) -> [0, N): n - 1 steps summing to N - 1, with flat runs (step 0) and
// skips (step > 1). n >= 2.
inline std::vector<int> RandomMonotoneWarp(std::mt19937_64& rng, int n, int N) {
  std::vector<int> steps(n - 1, 0);
  for (int i = 0; i < N - 1; ++i) {
    // Increments in clumps, so that both flats and skips occur.
    const int k = (rng() % 3 == 0) ? int(rng() % (n - 1)) : int(rng() % std::max(1, (n - 1) / 3));
    steps[k] += 1;
  }
  std::shuffle(steps.begin(), steps.end(), rng);
  std::vector<int> w(n, 0);
  for (int t = 1; t < n; ++t) w[t] = w[t - 1] + steps[t - 1];
  return w;
}

// value at t + shift belongs to t; the tail repeats the last value.
inline std::vector<double> MyShift(const std::vector<double>& v, int shift) {
  std::vector<double> out(v.size());
  for (std::size_t t = 0; t < v.size(); ++t)
    out[t] = v[std::min(t + std::size_t(shift), v.size() - 1)];
  return out;
}

// Sum-conserving eq. 6: each source frame's value shared equally among the reference frames mapped
// to it; skipped source frames added to the reference frame just before the skip.
inline std::vector<double> MyConservingWarp(const std::vector<double>& a,
                                            const std::vector<int>& w) {
  const int n = int(w.size());
  std::vector<int> count(a.size(), 0);
  for (int t = 0; t < n; ++t) ++count[w[t]];
  std::vector<double> out(n, 0.0);
  for (int t = 0; t < n; ++t) {
    out[t] = a[w[t]] / double(count[w[t]]);
    if (t + 1 < n) {
      for (int j = w[t] + 1; j < w[t + 1]; ++j) out[t] += a[j];
    }
  }
  return out;
}

}  // namespace mmh::montage::oracle
