// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/models/scan_beams.hpp"
#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// How a range-finder model joins the beams of a scan into one likelihood.
enum class BeamCombination {
  /// The product of the beam likelihoods (Probabilistic Robotics, Tables 6.1 and 6.3): beams
  /// taken as independent.
  product,
  /// nav2 AMCL's rule: p = 1 + sum over beams of pz^3 (its beam and likelihood-field models), a
  /// heuristic that tempers the independence assumption.
  nav2,
};

/// The likelihood-field range-finder model (Thrun, Burgard, Fox, Probabilistic Robotics,
/// Table 6.3; nav2 AMCL's likelihood_field): a beam ending at distance d from the nearest
/// occupied cell has pz = z_hit g(d) + z_rand / max_range, with g(d) = exp(-d^2 / 2 sigma^2)
/// (nav2), divided by sqrt(2 pi) sigma in the product combination (a normalised Gaussian, as
/// Table 6.3). d is capped at max_distance (nav2's laser_likelihood_max_dist), and an end
/// outside the map counts as max_distance away. Beams without a return are skipped.
///
/// The per-beam term depends on the end cell only, so it is tabulated once per map and max
/// range (log pz for the product, pz^3 for nav2's sum), as nav2 and beluga do: a beam then
/// costs a transform and one table read. Poses given to the model are robot poses; the laser's
/// mount in the robot frame is `sensor`.
struct LikelihoodFieldParams {
  double sigma_hit = 0.2;  ///< m (nav2's default)
  double z_hit = 0.95;
  double z_rand = 0.05;
  int max_beams = 0;  ///< nav2's max_beams; 0 = every beam
  double max_distance = 2.0;  ///< m, nav2's laser_likelihood_max_dist
  BeamCombination combination = BeamCombination::product;
  Pose2 sensor;  ///< the laser in the robot frame
  double agreement_tolerance = 0.2;  ///< m: a ray may enter a wall this far before its reading
  void validate() const;
};

class LikelihoodFieldModel : public SensorModel {
 public:
  LikelihoodFieldModel(const OccupancyGrid& map, const LikelihoodFieldParams& params = {});
  /// The scan of this step.
  void set_scan(const double* angles, const float* ranges, std::size_t n, double max_range);
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  std::size_t readings() const override { return beams_.size(); }
  double agreement(const Pose2& pose) const override;
  const LikelihoodFieldParams& params() const { return params_; }
  /// The tabulated per-cell term (log pz or pz^3) for the current max range, for tests.
  const cv::Mat& table() const { return table_; }
  /// The term of an end outside the map (that of max_distance), for the current max range.
  float outside() const { return outside_; }

 private:
  void tabulate(double max_range);
  double term(double d, double max_range) const;
  LikelihoodFieldParams params_;
  OccupancyGrid frame_;
  cv::Mat distance_;  // metres, CV_32F
  cv::Mat table_;     // CV_32F, per cell
  float outside_ = 0.0f;
  double table_range_ = -1.0;
  ScanBeams beams_;
  std::vector<double> end_x_, end_y_;  // beam ends in the sensor frame, in cells
  RangeCaster occupied_;
};

}  // namespace kiseki
