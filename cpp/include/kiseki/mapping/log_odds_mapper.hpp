// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// Inverse sensor model of a range finder in log-odds form (Thrun, Burgard, Fox,
/// Probabilistic Robotics, Table 9.1/9.2): l = l + l_hit at the beam's end cell, l + l_miss
/// along the cells the beam crosses. Defaults are OctoMap's (hit 0.7, miss 0.4, clamping 0.12 /
/// 0.97 as probabilities).
struct LogOddsParams {
  double resolution = 0.05;      ///< metres per cell
  double max_range = 80.0;       ///< readings >= max_range are "no return": free space only
  double usable_range = 30.0;    ///< free space is marked at most this far along a beam
                                 ///< (returns beyond it still mark their end cell)
  double min_range = 0.0;        ///< readings <= min_range are ignored
  /// Whether a "no return" reading (>= max_range) clears the cells along its beam up to
  /// usable_range. Off by default: indoors a missing return is more often glass, a black or
  /// specular surface, or an open door than truly empty space, and clearing along it erases
  /// walls seen from elsewhere.
  bool clear_on_no_return = false;
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamp_min = 0.12;
  double clamp_max = 0.97;
  double occupied_thresh = 0.65;  ///< p > this -> occupied (100) in the trinary map
  double free_thresh = 0.196;     ///< p < this -> free (0); in between or never seen -> unknown
};

void validate(const LogOddsParams& params);

/// A log-odds occupancy grid filled scan by scan from known sensor poses. Within one scan a cell
/// is updated at most once, and a cell hit by any beam is not also marked free by another
/// (OctoMap's rule for scan insertion).
class LogOddsMapper {
 public:
  /// A map covering [min_x, max_x] x [min_y, max_y] (world, metres, axis aligned).
  LogOddsMapper(double min_x, double min_y, double max_x, double max_y,
                const LogOddsParams& params);

  /// Adds one scan: beam i leaves sensor_pose at heading theta + angles[i] with ranges[i].
  /// Non-finite or negative ranges are skipped.
  void integrate_scan(const Pose2& sensor_pose, const float* ranges, const double* angles,
                      std::size_t n);

  /// Probabilities thresholded into a trinary ROS grid (0 / 100 / -1).
  OccupancyGrid to_occupancy() const;
  /// The log-odds values (CV_32FC1, row = y).
  const cv::Mat& log_odds() const { return log_odds_; }
  const OccupancyGrid& frame() const { return frame_; }
  std::size_t scans_integrated() const { return scans_; }

  /// Axis-aligned bounds of everything a set of scans can touch: every sensor position and
  /// every return's end point (and, when no-return readings clear, their beams clipped to
  /// usable_range). poses is n_scans x 3 (x, y, theta), ranges
  /// n_scans x n_beams, row-major. Returns {min_x, min_y, max_x, max_y}.
  static std::vector<double> scan_bounds(const double* poses, const float* ranges,
                                         const double* angles, std::size_t n_scans,
                                         std::size_t n_beams, const LogOddsParams& params);

 private:
  LogOddsParams params_;
  OccupancyGrid frame_;  // geometry only; its cells are not used
  cv::Mat log_odds_;
  std::vector<std::uint32_t> hit_stamp_, miss_stamp_;
  std::vector<int> hit_cells_;
  std::uint32_t scans_ = 0;
  float l_hit_, l_miss_, l_min_, l_max_;
};

/// Share of scan endpoints (readings below max_range) whose cell, or one of its 8 neighbours
/// when neighbourhood is 1, is occupied (value >= occupied_threshold) in the grid. Endpoints
/// outside the grid count as misses. Returns {hits, endpoints}.
std::pair<std::size_t, std::size_t> endpoint_agreement(
    const OccupancyGrid& grid, const double* poses, const float* ranges, const double* angles,
    std::size_t n_scans, std::size_t n_beams, double max_range, int neighbourhood = 1,
    std::int8_t occupied_threshold = 65);

}  // namespace kiseki
