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

/// The smallest sigma_hit of the range models (m): below it the Gaussian's variance underflows
/// (1e-300 squared is 0) and a beam's likelihood becomes 0 / 0.
inline constexpr double kMinSigmaHit = 1e-6;

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
///
/// Beam skipping (nav2's do_beamskip, off by default): a beam that ends near a wall for few
/// particles probably hit something the map does not hold (a person, a door left open), and
/// weighing with it only spreads the cloud. select_readings(cloud) counts, per beam, the
/// particles whose end of that beam lies within beam_skip_distance of an occupied cell; a beam
/// is used when that count is at least beam_skip_threshold x the cloud's size. When more than
/// beam_skip_error_threshold of the beams would be skipped the cloud itself is probably wrong
/// (not the beams), and every beam is used. The counts are integers summed over disjoint
/// ranges of particles, so the choice is the same for any thread count. set_scan() uses every
/// beam until select_readings() is called (the engine calls it in update()).
struct LikelihoodFieldParams {
  double sigma_hit = 0.2;  ///< m (nav2's default)
  double z_hit = 0.95;
  double z_rand = 0.05;
  int max_beams = 0;  ///< nav2's max_beams; 0 = every beam
  double max_distance = 2.0;  ///< m, nav2's laser_likelihood_max_dist
  BeamCombination combination = BeamCombination::product;
  Pose2 sensor;  ///< the laser in the robot frame
  double agreement_tolerance = 0.2;  ///< m: a ray may enter a wall this far before its reading
  bool beam_skip = false;               ///< nav2's do_beamskip
  double beam_skip_distance = 0.5;      ///< m, nav2's beam_skip_distance
  double beam_skip_threshold = 0.3;     ///< share of particles, nav2's beam_skip_threshold
  double beam_skip_error_threshold = 0.9;  ///< share of beams, nav2's beam_skip_error_threshold
  void validate() const;
};

class LikelihoodFieldModel : public SensorModel {
 public:
  LikelihoodFieldModel(const OccupancyGrid& map, const LikelihoodFieldParams& params = {});
  /// The scan of this step.
  void set_scan(const double* angles, const float* ranges, std::size_t n, double max_range);
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  /// The beams weighed with: every beam of the scan, or those beam skipping keeps.
  std::size_t readings() const override { return used_.size(); }
  /// Beam skipping over this cloud (see above); nothing unless params().beam_skip.
  void select_readings(const Pose2* poses, std::size_t n, int threads) override;
  /// The indices, among the scan's beams with a return, of the beams weighed with.
  const std::vector<std::size_t>& used_beams() const { return used_; }
  /// How many beams the scan has after max_beams and without the beams with no return.
  std::size_t beams() const { return beams_.size(); }
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
  void use(std::vector<std::size_t> beams);
  std::vector<double> end_x_, end_y_;  // beam ends in the sensor frame, in cells
  std::vector<std::size_t> used_;       // the beams weighed with
  std::vector<double> used_x_, used_y_;  // their ends (end_x_, end_y_ of used_)
  RangeCaster occupied_;
};

}  // namespace kiseki
