// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <vector>

#include "kiseki/core/pose.hpp"
#include "kiseki/core/random.hpp"

namespace kiseki {

/// Parameters of the particle filter. The motion model is the odometry model of Thrun, Burgard
/// and Fox, Probabilistic Robotics, Table 5.6 (rotation, translation, rotation, each with noise
/// whose variance grows with the motion: alpha1 rot->rot, alpha2 trans->rot, alpha3
/// trans->trans, alpha4 rot->trans).
struct ParticleFilterParams {
  int particles = 1000;
  double alpha1 = 0.05, alpha2 = 0.01, alpha3 = 0.05, alpha4 = 0.01;
  double resample_threshold = 0.5;  ///< resample when ESS < threshold * particles
  void validate() const;
};

/// A particle filter over planar poses: prediction from odometry increments, weighting by any
/// likelihood, weighted-mean estimate, low-variance resampling when the effective sample size
/// drops (Probabilistic Robotics, Table 4.4).
class ParticleFilter {
 public:
  ParticleFilter(const ParticleFilterParams& params, std::uint64_t seed);

  /// Particles drawn around a pose with the given standard deviations (m, m, rad).
  void initialize(const Pose2& mean, double sd_x, double sd_y, double sd_theta);
  void set_particles(const std::vector<Pose2>& particles);
  /// Moves every particle by the odometry increment between two odometry poses, with noise.
  /// An increment under 1 cm is a turn on the spot (no rot1), and a backward move has the
  /// noise of a forward one (rotations near pi enter the noise as their distance from pi).
  void predict(const Pose2& odom_before, const Pose2& odom_after);
  /// Multiplies the weights by likelihoods (one per particle) and normalises. If every
  /// likelihood is zero the weights are left uniform and false is returned.
  bool weight(const std::vector<double>& likelihoods);
  /// Low-variance resampling if ESS < threshold * n; returns whether it resampled.
  bool resample_if_needed();
  double effective_sample_size() const;
  /// Weighted mean (circular mean of the headings).
  Pose2 estimate() const;

  const std::vector<Pose2>& particles() const { return particles_; }
  const std::vector<double>& weights() const { return weights_; }
  const ParticleFilterParams& params() const { return params_; }

 private:
  void resample();
  ParticleFilterParams params_;
  Random rng_;
  std::vector<Pose2> particles_;
  std::vector<double> weights_;
};

}  // namespace kiseki
