// Reproducible random numbers for the simulated people (performances, annotators, viewers).
// Every draw comes from the raw 64-bit output of std::mt19937_64 (fully specified by the C++
// standard) turned into doubles and normals by our own code, so that a seed gives the same
// numbers with every standard library; std::normal_distribution is implementation-defined.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <random>

namespace mmh::people {

// A seed for one independent stream, derived from a base seed and tags (animator, take, ...), so
// that streams never depend on the order in which they are drawn (SplitMix64 finaliser chain).
std::uint64_t DeriveSeed(std::uint64_t seed, std::initializer_list<std::uint64_t> tags);

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  // Uniform on [0, 1), 53 random bits.
  double Uniform();
  // Uniform on [a, b).
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  // Standard normal (Marsaglia's polar method).
  double Normal();
  double Normal(double mean, double sd) { return mean + sd * Normal(); }
  // True with probability p.
  bool Bernoulli(double p) { return Uniform() < p; }
  // Uniform integer in [0, n), n >= 1 (rejection, no modulo bias).
  int Index(int n);
  // Exponential with the given mean.
  double Exponential(double mean);

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace mmh::people
