// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/grid/sector_caster.hpp"
#include "kiseki/models/likelihood_field.hpp"
#include "kiseki/models/scan_beams.hpp"
#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// The beam range-finder model (Probabilistic Robotics, Table 6.1; nav2 AMCL's "beam" model):
/// each beam's reading z is compared with the range z* ray-cast in the map from the particle,
/// pz = z_hit exp(-(z - z*)^2 / 2 sigma_hit^2)            (measurement noise)
///    + z_short lambda_short exp(-lambda_short z)  if z < z* (unexpected objects)
///    + z_max                                      if z is a no-return (at max range)
///    + z_rand / max_range                         if z < max_range (random readings),
/// the Gaussian divided by sqrt(2 pi) sigma_hit in the product combination. A ray stops at an
/// occupied cell and, as in nav2, at an unknown one (unknown_stops). Readings of +inf or at or
/// beyond max range are no-returns and score with z_max; NaN, zero and negative readings are
/// skipped. Ray casting skips free space with the swept-sector table (SectorCaster) or a
/// distance field (RangeCaster), both exact, and a ray stops 8 sigma_hit past its reading, where
/// the Gaussian term has vanished and a longer z* scores the same.
/// The largest swept-sector table a beam model builds (bytes).
inline constexpr std::size_t kMaxSectorTableBytes = std::size_t{512} << 20;

struct BeamModelParams {
  double z_hit = 0.5, z_short = 0.05, z_max = 0.05, z_rand = 0.5;  ///< nav2's defaults
  double sigma_hit = 0.2;     ///< m
  double lambda_short = 0.1;  ///< 1/m
  int max_beams = 0;          ///< nav2's max_beams; 0 = every beam
  bool unknown_stops = true;
  /// How z* is cast (the same z* either way). A swept-sector table larger than
  /// kMaxSectorTableBytes (64 bytes a cell: a map of over 8.4 million cells) is not built: the
  /// distance field casts instead, and caster() says so.
  RayCasterKind caster = RayCasterKind::swept_sector;
  BeamCombination combination = BeamCombination::product;
  Pose2 sensor;  ///< the laser in the robot frame
  double agreement_tolerance = 0.2;
  void validate() const;
};

class BeamModel : public SensorModel {
 public:
  BeamModel(const OccupancyGrid& map, const BeamModelParams& params = {});
  void set_scan(const double* angles, const float* ranges, std::size_t n, double max_range);
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  std::size_t readings() const override { return beams_.size(); }
  double agreement(const Pose2& pose) const override;
  /// The mixture pz of one beam: reading z, expected range z_star.
  double beam_probability(double z, double z_star, bool no_return) const;
  /// The caster that casts z*: the one asked for, or the distance field for a map whose
  /// swept-sector table would exceed kMaxSectorTableBytes.
  RayCasterKind caster() const { return sector_ ? RayCasterKind::swept_sector : RayCasterKind::distance_field; }

 private:
  BeamModelParams params_;
  ScanBeams beams_;
  // z* of every beam from a sensor pose, each ray cast up to reach[b].
  void expected_ranges(const Pose2& sensor, const double* reach, double* z_star) const;

  std::optional<RangeCaster> field_;    // the caster of z*: one of these two
  std::optional<SectorCaster> sector_;
  RangeCaster occupied_;
  std::vector<double> short_term_, floor_term_;  // z_short's and z_max's or z_rand's, per beam
  bool has_scan_ = false;
};

}  // namespace kiseki
