// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// The likelihood-field range-finder model (Thrun, Burgard, Fox, Probabilistic Robotics,
/// Table 6.3), the standard baseline of grid-map MCL (nav2 AMCL's default): each beam end's
/// distance d to the nearest occupied cell scores z_hit N(d; 0, sigma_hit) + z_rand / max_range;
/// beams at max range are skipped; the likelihood is the product over the used beams.
struct LikelihoodFieldParams {
  double sigma_hit = 0.2;  ///< m (nav2 AMCL default)
  double z_hit = 0.95;
  double z_rand = 0.05;
  int beam_stride = 1;     ///< use every k-th beam (AMCL's max_beams)
  void validate() const;
};

class LikelihoodFieldModel {
 public:
  LikelihoodFieldModel(const OccupancyGrid& map, const LikelihoodFieldParams& params = {});
  /// The scan of this step: sensor offset in the robot frame is applied by the caller (poses
  /// given to likelihoods() are sensor poses).
  void set_scan(const double* angles, const float* ranges, std::size_t n, double max_range);
  /// Log-likelihoods of n sensor poses (row-major n x 3).
  void log_likelihoods(const double* poses, std::size_t n, double* out) const;

 private:
  LikelihoodFieldParams params_;
  OccupancyGrid frame_;
  cv::Mat distance_;  // metres, CV_32F
  std::vector<double> cos_, sin_, range_;
  double max_range_ = 0.0;
};

}  // namespace kiseki
