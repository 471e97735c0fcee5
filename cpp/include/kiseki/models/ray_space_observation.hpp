// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/models/likelihood_field.hpp"
#include "kiseki/models/scan_beams.hpp"
#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// kiseki's ray space observation model: the teaching-and-playback thesis' two errors of a
/// scan against the map (sec. 3.3: free space seen where the map has a wall, "penetration",
/// costly; a wall seen where the map has free space, "intrusion", cheap) read beam by beam along
/// each ray at the sensor's full range, together with where the beam ends. It is not the
/// thesis' model (that one is SpaceObservationModel, kept as printed); see the README for the
/// comparison. For a beam with reading r from the sensor pose of a particle:
///
///   r^   = the range to the first occupied map cell along the beam, at most r (unknown cells
///          and the map's edge do not stop it);
///   delta = r - r^, the penetration depth (0 when the ray reaches its reading unobstructed);
///   d    = the distance from the beam's end to the nearest occupied cell, at most max_distance
///          (an end outside the map: max_distance), as in the likelihood field;
///   h    = max(d, delta);
///   pz   = z_hit N(h; 0, sigma_hit)                           (the end lies on a mapped wall)
///        + z_intrusion lambda_short exp(-lambda_short r)  if delta = 0 (an unmapped object
///                                                               stopped it)
///        + z_rand / max_range                                 (anything else),
///   log p(z | x) = sum over beams of log pz.
///
/// Why each part, against the models beside it:
/// * the end term (d) is the likelihood field's: a pose is scored by where beams end, at the
///   sensor's full range, so a wall across a corridor 10 m ahead pins the pose along it (the
///   thesis' model looks only 4 m around the robot and does not score where beams stop);
/// * delta is the thesis' penetration, per beam: a beam that passes through a mapped wall is
///   scored by how far past the wall it ends, so the wall is never "near" it as the likelihood
///   field would count a wall behind the end (the likelihood field ignores the ray);
/// * the intrusion term is the thesis' cheap intrusion: a beam that ends in free space without
///   passing a wall is explained by an object the map does not hold, with the beam model's
///   density of unexpected objects (Probabilistic Robotics, Table 6.1; nav2's lambda_short).
///   Its weight z_intrusion equals z_hit: a map says nothing about what it does not hold, so a
///   beam's end is given equal prior odds of a mapped and an unmapped cause. (The beam model's
///   z_short = 0.05 makes an unmapped object 19 times less likely than a wall; with it,
///   unmapped obstacles at 4 per 10 m of the Intel log pulled the estimate away, see the
///   README.) A penetrating beam gets no such term, so intrusion stays cheaper than
///   penetration, as sigma_intrusion = 13 sigma_penetration makes it in the thesis.
/// No-return beams are skipped, as in the likelihood field.
struct RaySpaceObservationParams {
  double sigma_hit = 0.2;     ///< m (nav2's)
  double z_hit = 0.95;        ///< Probabilistic Robotics' likelihood field
  double z_rand = 0.05;
  double z_intrusion = 0.95;  ///< = z_hit: equal odds of a mapped and an unmapped cause
  double lambda_short = 0.1;  ///< 1/m, nav2's beam model
  double max_distance = 2.0;  ///< m, nav2's laser_likelihood_max_dist
  int max_beams = 0;          ///< nav2's max_beams; 0 = every beam
  Pose2 sensor;               ///< the laser in the robot frame
  double agreement_tolerance = 0.2;
  /// The agreement (ScanBeams::agreement) leaves out the beams the intrusion term explains:
  /// a beam ending in the open is then no sign of being lost, as it costs this model little.
  /// A reset's proposed place is still judged with every beam (placement_agreement).
  bool agreement_skips_intrusion = false;
  void validate() const;
};

class RaySpaceObservationModel : public SensorModel {
 public:
  RaySpaceObservationModel(const OccupancyGrid& map, const RaySpaceObservationParams& params = {});
  void set_scan(const double* angles, const float* ranges, std::size_t n, double max_range);
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  std::size_t readings() const override { return beams_.size(); }
  double agreement(const Pose2& pose) const override;
  /// The plain agreement (every returning beam counted), whichever agreement() is.
  double placement_agreement(const Pose2& pose) const override;
  const RaySpaceObservationParams& params() const { return params_; }
  /// pz of one beam from its penetration depth delta and its end's distance d (capped).
  double beam_probability(double r, double delta, double d) const;

 private:
  RaySpaceObservationParams params_;
  OccupancyGrid frame_;
  cv::Mat distance_;  // metres, CV_32F, capped at max_distance
  ScanBeams beams_;
  std::vector<double> intrusion_;  // per beam: z_intrusion lambda exp(-lambda r), pose-free
  RangeCaster occupied_;
  bool has_scan_ = false;
};

}  // namespace kiseki
