// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <random>

namespace kiseki {

/// Mixes a seed and a stream index into a new 64-bit seed (SplitMix64 finaliser).
/// Used to give every trial, robot or sensor its own independent, reproducible stream.
std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream);

/// The one seeded random generator used by every stochastic part of kiseki.
///
/// The engine is std::mt19937_64, whose output sequence the C++ standard fixes; the
/// distributions are implemented here (not with std::*_distribution, whose algorithms differ
/// between standard libraries), so one seed gives the same numbers on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed);

  std::uint64_t seed() const { return seed_; }
  /// Uniform double in [0, 1) with 53 random bits.
  double uniform();
  /// Uniform double in [low, high).
  double uniform(double low, double high);
  /// Standard normal sample (Marsaglia polar method), scaled: mean + stddev * z.
  double normal(double mean = 0.0, double stddev = 1.0);
  /// Uniform integer in [0, n), without modulo bias. n must be positive.
  std::uint64_t below(std::uint64_t n);
  /// A generator for sub-stream index, independent of this one's state.
  Random split(std::uint64_t stream) const { return Random(derive_seed(seed_, stream)); }

 private:
  std::uint64_t seed_;
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// A light generator for one particle of one step: SplitMix64 (Steele, Lea and Flood, "Fast
/// splittable pseudorandom number generators", OOPSLA 2014) from derive_seed(step, particle).
/// Every particle of a step draws its own stream, so the numbers a particle gets do not depend
/// on which thread moves it: the same seed gives the same particles for any thread count.
/// Construction is two additions, where a std::mt19937_64 would fill 312 words.
class StreamRandom {
 public:
  StreamRandom(std::uint64_t seed, std::uint64_t stream) : state_(derive_seed(seed, stream)) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double low, double high) { return low + (high - low) * uniform(); }
  /// Standard normal sample by the Marsaglia polar method, scaled: mean + stddev * z.
  double normal(double mean = 0.0, double stddev = 1.0);

 private:
  std::uint64_t state_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace kiseki
