// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// What MonteCarloLocalization's cloud says: its weighted mean, covariance and effective sample
// size, each summed in particle order (the same for any thread count).
#include <cmath>
#include <vector>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/filters/monte_carlo_localization.hpp"

namespace kiseki {

Pose2 MonteCarloLocalization::estimate() const {
  check_ready();
  const std::size_t n = particles_.size();
  double x = 0, y = 0, c = 0, s = 0;
  if (n < 2 * kParallelExps || resolve_threads(threads_now()) < 2) {
    for (std::size_t i = 0; i < n; ++i) {
      const double w = weights_[i];
      x += w * particles_[i].x;
      y += w * particles_[i].y;
      c += w * std::cos(particles_[i].theta);
      s += w * std::sin(particles_[i].theta);
    }
    return {x, y, std::atan2(s, c)};
  }
  // The headings' cosines and sines on the threads, the sums in particle order as above.
  std::vector<double> cosines(n), sines(n);
  parallel_for(n, threads_now(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) cosines[i] = std::cos(particles_[i].theta), sines[i] = std::sin(particles_[i].theta);
  }, kParallelExps);
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weights_[i];
    x += w * particles_[i].x;
    y += w * particles_[i].y;
    c += w * cosines[i];
    s += w * sines[i];
  }
  return {x, y, std::atan2(s, c)};
}

Eigen::Matrix3d MonteCarloLocalization::covariance() const {
  const Pose2 m = estimate();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Eigen::Vector3d d(particles_[i].x - m.x, particles_[i].y - m.y, angle_difference(particles_[i].theta, m.theta));
    cov += weights_[i] * d * d.transpose();
  }
  return cov;
}

double MonteCarloLocalization::effective_sample_size() const { return kiseki::effective_sample_size(weights_); }

}  // namespace kiseki
