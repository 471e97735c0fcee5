// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "kiseki/core/pose.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/filters/correlative_scan_matcher.hpp"

namespace kiseki {

/// Where a sensor reset (Lenser and Veloso, 2000) draws its candidate poses from.
enum class ResetProposal {
  /// sensor_reset_candidates poses uniform over the free cells.
  uniform,
  /// The same number of poses around the correlative scan matcher's k best hypotheses for the
  /// current scan (Olson 2009; Hess et al. 2016, Algorithm 3): the proposal of Thrun, Fox,
  /// Burgard and Dellaert's Mixture-MCL ("Robust Monte Carlo localization for mobile robots",
  /// AIJ 2001, sec. 3: poses drawn from the measurement, x ~ p(z | x)), with the search made
  /// exact over the map's lattice instead of sampled.
  matcher,
};
ResetProposal reset_proposal_from_name(const std::string& name);
const char* reset_proposal_name(ResetProposal proposal);

/// One scan as the matcher reads it: n beam angles (rad) and ranges (m) in the laser frame.
struct ScanView {
  const double* angles = nullptr;
  const float* ranges = nullptr;
  std::size_t n = 0;
};

/// `count` poses around ranked hypotheses: hypothesis i gets a share proportional to
/// exp(power (score_i - best score)) (its score as a tempered log-likelihood; the largest
/// remainders round the shares to whole poses, ties to the better rank), each pose drawn from
/// a Gaussian of sd_xy per axis and sd_theta around it. The Python one-scan start's
/// hypothesis_cloud (kiseki.filters.relocalization) draws the same shares. Needs a hypothesis.
std::vector<Pose2> poses_around_hypotheses(const std::vector<PoseHypothesis>& hypotheses, std::size_t count,
                                           double sd_xy, double sd_theta, double power, Random& rng);

/// The look-elsewhere term of a reset's acceptance, ln N for a proposal that took its best of
/// N poses. The rule: before the scan, "the robot is where the cloud is" and "it is somewhere
/// else" have even odds, and the second spreads its prior evenly over the N poses searched; the
/// posterior odds of the best searched pose against the cloud's best are then its likelihood
/// ratio divided by N, and a reset asks those odds to exceed exp(reset_evidence):
/// ln L_best - ln L_cloud > reset_evidence + ln N (the Bonferroni factor of N looks).
double look_elsewhere_term(double searched);

}  // namespace kiseki
