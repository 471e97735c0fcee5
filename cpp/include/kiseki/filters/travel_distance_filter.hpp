// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/core/random.hpp"
#include "kiseki/filters/kld_sampling.hpp"
#include "kiseki/filters/resampling.hpp"

namespace kiseki {

struct TravelDistanceParams {
  std::size_t particles = 1000;  ///< the count; with kld the maximum
  bool kld = false;
  KldParams kld_params;  ///< bin_distance is the bin; max_particles is taken from `particles`
  ResamplingMethod resampling = ResamplingMethod::systematic;
  double resample_threshold = 0.5;
  double likelihood_power = 1.0;
  int threads = 0;
  void validate() const;
};

/// A particle filter over a 1-D state: the distance travelled along a taught path (the magnetic
/// thesis' travel-distance filter). It shares resampling, ESS gating and KLD sampling with the
/// SE(2) engine; the likelihoods come from any model over distances (a magnetic map along the
/// path, for instance), as log-likelihoods, one per particle.
class TravelDistanceFilter {
 public:
  TravelDistanceFilter(const TravelDistanceParams& params, std::uint64_t seed);
  void initialize(double mean, double sd);
  void set_particles(const std::vector<double>& distances, const std::vector<double>& weights = {});
  void set_weights(const std::vector<double>& weights);
  /// Every particle travels `distance` plus Gaussian noise of SD `sd`; particle i draws from its
  /// own stream, so the result does not depend on the thread count.
  void predict(double distance, double sd);
  /// Weighs by log-likelihoods (one per particle); resamples when ESS < threshold * n (KLD
  /// adapts the count). Returns whether the weights changed.
  bool update(const std::vector<double>& log_likelihoods);
  double estimate() const;
  double variance() const;
  double effective_sample_size() const;
  const std::vector<double>& particles() const { return particles_; }
  const std::vector<double>& weights() const { return weights_; }

 private:
  TravelDistanceParams params_;
  Random rng_;
  std::vector<double> particles_, weights_;
};

}  // namespace kiseki
