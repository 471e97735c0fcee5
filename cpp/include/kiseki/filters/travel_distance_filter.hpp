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
///
/// Each particle also carries an odometry scale k (1 unless set): `predict_scaled` moves it by
/// k times the odometry's distance and lets k wander, so a filter can follow an odometry whose
/// scale is off (kiseki's loop filter). Resampling keeps each particle's k with its distance.
class TravelDistanceFilter {
 public:
  TravelDistanceFilter(const TravelDistanceParams& params, std::uint64_t seed);
  void initialize(double mean, double sd);
  void set_particles(const std::vector<double>& distances, const std::vector<double>& weights = {});
  void set_weights(const std::vector<double>& weights);
  /// One scale per particle, each finite and > 0.
  void set_scales(const std::vector<double>& scales);
  /// Every particle travels `distance` plus Gaussian noise of SD `sd`; particle i draws from its
  /// own stream, so the result does not depend on the thread count.
  void predict(double distance, double sd);
  /// k_i += N(0, scale_sd^2), then d_i += k_i * distance + N(0, sd^2) (a k that would fall to
  /// 0 or below keeps its value); the same per-particle streams as `predict`.
  void predict_scaled(double distance, double sd, double scale_sd);
  /// Weighs by log-likelihoods (one per particle); resamples when ESS < threshold * n (KLD
  /// adapts the count). Returns whether the weights changed.
  bool update(const std::vector<double>& log_likelihoods);
  double estimate() const;
  double variance() const;
  double effective_sample_size() const;
  const std::vector<double>& particles() const { return particles_; }
  const std::vector<double>& weights() const { return weights_; }
  const std::vector<double>& scales() const { return scales_; }

 private:
  TravelDistanceParams params_;
  Random rng_;
  std::vector<double> particles_, weights_, scales_;
};

}  // namespace kiseki
