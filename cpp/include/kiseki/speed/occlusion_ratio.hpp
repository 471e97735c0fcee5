// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// A planar scan in the sensor frame: n beam angles (rad, strictly increasing) and ranges (m).
/// A reading >= max_range is no return (free space seen up to max_range); a NaN reading says
/// nothing (its direction counts as unseen).
struct PlanarScan {
  const double* angles = nullptr;
  const float* ranges = nullptr;
  std::size_t size = 0;
  double max_range = 0.0;
};

/// What the occlusion ratio looks at.
struct OcclusionRatioOptions {
  double half_angle = 1.5707963267948966;  ///< theta (rad): the region is +-theta of the heading
  /// Map cells with 0 <= value <= free_threshold are free (nav2 map_server's free_thresh 0.25).
  std::int8_t free_threshold = 25;
};

/// The ratio of eq. 1 and the two cell counts behind it.
struct OcclusionRatio {
  double ratio = 1.0;            ///< seen / free, 1 when the region has no free cell
  std::size_t seen_cells = 0;    ///< |R_recognize(theta)|
  std::size_t free_cells = 0;    ///< |R_map_free intersect R_sensor(theta)|
};

/// Occlusion ratio of Yorozu, Moriguchi and Takahashi's speed control, eq. 1:
///
///   v_max^ref = v_max * R_recognize(theta) / (R_map_free intersect R_sensor(theta))
///
/// counted in cells of the prior map. R_map_free intersect R_sensor(theta) are the map's free
/// cells whose centres lie within max_range of the sensor and within +-theta of the heading
/// (the direction of motion, in the map frame), whether the map's own walls hide them or not:
/// a known corner or crossing shrinks the ratio, as the paper wants. R_recognize(theta) are
/// those of them that the current scan sees: a cell is seen when the beam nearest to its
/// bearing (each beam covers the wedge halfway to its neighbours; outside the scan's field of
/// view nothing is seen) passes its centre at least half a cell before the beam's end, so the
/// cell of an unknown obstacle and everything behind it are not seen.
///
/// labels, when given, receives the map's size in CV_8UC1: 0 outside the region, 1 a free cell
/// of the region not seen (occluded), 2 a seen one (for pictures).
OcclusionRatio occlusion_ratio(const OccupancyGrid& map, const Pose2& sensor_pose, const PlanarScan& scan,
                               double heading, const OcclusionRatioOptions& options,
                               cv::Mat* labels = nullptr);

/// Checks a scan (n >= 1, finite increasing angles, max_range > 0, ranges not negative);
/// throws std::invalid_argument naming the problem.
void check_scan(const PlanarScan& scan);

}  // namespace kiseki
