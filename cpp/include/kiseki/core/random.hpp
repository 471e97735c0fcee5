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

}  // namespace kiseki
