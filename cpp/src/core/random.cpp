// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/random.hpp"

#include <cmath>
#include <stdexcept>

namespace kiseki {

std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Random::Random(std::uint64_t seed) : seed_(seed), engine_(seed) {}

double Random::uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

double Random::uniform(double low, double high) { return low + (high - low) * uniform(); }

namespace {
// Marsaglia's polar method: two normal samples from a uniform point in the unit disc; the
// second is kept for the next call.
template <typename Generator>
double polar_normal(Generator& g, bool& has_spare, double& spare) {
  if (has_spare) {
    has_spare = false;
    return spare;
  }
  double u = 0.0, v = 0.0, s = 0.0;
  do {
    u = 2.0 * g.uniform() - 1.0;
    v = 2.0 * g.uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare = v * factor;
  has_spare = true;
  return u * factor;
}
}  // namespace

double Random::normal(double mean, double stddev) {
  return mean + stddev * polar_normal(*this, has_spare_, spare_);
}

double StreamRandom::normal(double mean, double stddev) {
  return mean + stddev * polar_normal(*this, has_spare_, spare_);
}

std::uint64_t Random::below(std::uint64_t n) {
  if (n == 0) throw std::invalid_argument("Random::below: n must be positive");
  const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % n);
  std::uint64_t r = engine_();
  while (r >= limit) r = engine_();
  return r % n;
}

}  // namespace kiseki
