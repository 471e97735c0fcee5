// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <limits>

#include "kiseki/core/pose.hpp"

namespace kiseki {

/// What the Monte Carlo engine (kiseki/filters) asks of a measurement model: the
/// log-likelihood log p(z | x) of the current measurement at each particle pose. Every sensor
/// model (likelihood field, beam, space observation, and models written elsewhere, such as the
/// magnetic ones) implements this; the measurement itself is given to the model before the
/// update (set_scan, set_local_map, ...).
///
/// log_likelihoods() is called from several threads at once on disjoint ranges of poses: it
/// must not change the model. A pose where the measurement is impossible gets -inf; NaN is an
/// error.
class SensorModel {
 public:
  virtual ~SensorModel() = default;
  /// Log-likelihoods of n robot poses.
  virtual void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const = 0;
  /// How many independent readings one measurement holds (the beams used of a scan). The
  /// engine divides log-likelihoods by it to compare scans with different numbers of returns
  /// (Augmented MCL's average likelihood).
  virtual std::size_t readings() const { return 1; }
  /// The share, in [0, 1], of the measurement that agrees with the map seen from one pose, or
  /// NaN when the model cannot tell. For scans: the share of beams whose ray does not pass
  /// through an occupied cell before its end (emcl2's "non-penetration") and that end at a wall
  /// (ScanBeams::agreement, whose intrusion-tolerant form leaves out beams ending in the open).
  /// The engine's resetting trigger and its reliability estimate use it.
  virtual double agreement(const Pose2& /*pose*/) const {
    return std::numeric_limits<double>::quiet_NaN();
  }
  /// The agreement by which a reset's proposed place is judged, and the cloud's place against
  /// it: agreement() itself, unless a model judges being lost by a laxer measure than a new
  /// place (the ray model's intrusion-tolerant agreement, under which a wrong place in a wider
  /// space, whose beams end in the open, would pass).
  virtual double placement_agreement(const Pose2& pose) const { return agreement(pose); }
  /// Called by the engine with the whole cloud before it weighs it, once per update (after
  /// the measurement was set): a model that chooses which readings to use from where the
  /// particles are (the likelihood field's beam skipping) does it here, on up to `threads`
  /// threads, with a result that must not depend on their number. Nothing by default.
  virtual void select_readings(const Pose2* /*poses*/, std::size_t /*n*/, int /*threads*/) {}
};

}  // namespace kiseki
