// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "kiseki/core/pose.hpp"

namespace kiseki {

/// Sampling motion models driven by an odometry increment (odom_before -> odom_after).
///
/// differential: the odometry model of Probabilistic Robotics, Table 5.6 (rotation,
/// translation, rotation with noise SDs sqrt(alpha1 rot^2 + alpha2 trans^2) on the rotations and
/// sqrt(alpha3 trans^2 + alpha4 (rot1^2 + rot2^2)) on the translation). An increment under 1 cm
/// is a turn on the spot (nav2's rule: the direction of a millimetre of slip says nothing), and a
/// backward move has the noise of a forward one (the rotations enter the noise folded to
/// [0, pi/2]).
///
/// omnidirectional: nav2 AMCL's omni model: the translation along the increment's bearing in
/// each particle's frame with SD sqrt(alpha3 trans^2 + alpha1 rot^2), a sideways (strafe) error
/// with SD sqrt(alpha1 rot^2 + alpha5 trans^2) and the rotation with SD
/// sqrt(alpha4 rot^2 + alpha2 trans^2). The alphas mean what nav2 documents for each model.
enum class MotionModelType { differential, omnidirectional };
MotionModelType motion_model_from_name(const std::string& name);

struct MotionParams {
  MotionModelType type = MotionModelType::differential;
  double alpha1 = 0.05, alpha2 = 0.01, alpha3 = 0.05, alpha4 = 0.01, alpha5 = 0.01;
  void validate() const;
};

/// Moves n particles in place by the increment, with noise. Particle i draws its noise from
/// StreamRandom(seed, i), so the result does not depend on `threads` (0 = all cores).
/// Throws std::invalid_argument for a non-finite increment.
void sample_motion(const MotionParams& params, const Pose2& odom_before, const Pose2& odom_after,
                   Pose2* particles, std::size_t n, std::uint64_t seed, int threads);

}  // namespace kiseki
