// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <vector>

#include "kiseki/core/pose.hpp"
#include "kiseki/grid/range_caster.hpp"

namespace kiseki {

/// The beams of one 2-D laser scan that a range-finder model uses, in the laser frame.
///
/// Beam selection is nav2 AMCL's max_beams rule: every step-th beam from the first, step =
/// (beams - 1) / (max_beams - 1) in integers (at least 1); max_beams = 0 takes every beam.
/// Readings: NaN, zero and negative ranges are invalid and skipped; +inf and readings at or
/// beyond max_range are "no return" (kept, flagged, only when keep_no_return: the beam model's
/// z_max term; the likelihood field skips them as nav2 does).
struct ScanBeams {
  std::vector<double> angle, cos, sin, range;
  std::vector<char> no_return;
  double max_range = 0.0;
  std::size_t returns = 0;  ///< beams with a reading below max_range

  void set(const double* angles, const float* ranges, std::size_t n, double max_range,
           int max_beams, bool keep_no_return);
  std::size_t size() const { return range.size(); }

  /// The share of returning beams that agree with the map seen from the sensor pose: the ray
  /// reaches its reading (less a tolerance) without entering an occupied cell (emcl2's
  /// non-penetration; unknown cells do not stop it) and the reading ends within the tolerance
  /// (plus one cell, for the cell-centre distances) of an occupied cell. The tolerance is
  /// `tolerance` plus 0.02 x the range (a heading error of 1.1 degrees). The second test
  /// catches a pose in a wider space than the real one, whose beams end in the open and
  /// penetrate nothing. 0 when the sensor is not on a free cell (0..19) of the map; NaN when
  /// no beam returned.
  ///
  /// With `skip_intrusion`, a beam that penetrates nothing and ends in the open (an intrusion:
  /// what an object the map does not hold reads) neither agrees nor disagrees: the share is
  /// taken over the beams that end at a wall or pass through one, NaN when there are none.
  /// The second test above then no longer catches a pose in a wider space: such a share must
  /// not judge a new place (SensorModel::placement_agreement).
  double agreement(const RangeCaster& occupied, const Pose2& sensor, double tolerance,
                   bool skip_intrusion = false) const;
};

}  // namespace kiseki
