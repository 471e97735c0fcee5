// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/sim/depth_camera.hpp"

namespace kiseki {

/// The teaching-and-playback thesis' local map L (sec. 3.3): a square around the robot in the
/// robot frame (x forward), cells free (0: a beam passed), occupied (100: a beam ended there,
/// or the cell lies behind such an end, unseen) or outside the field of view (-1).
struct LocalMapParams {
  double size = 8.0;        ///< metres (the thesis: 8.0 m x 8.0 m)
  double resolution = 0.1;  ///< metres per cell (the thesis: 0.1 m)
  void validate() const;
};

/// Accumulates beams from any number of sensors, then resolves each cell: a beam's end cell
/// is occupied; a cell a beam crossed is free unless some beam ended in it; a cell only ever
/// behind an end is occupied (the thesis' "space behind the obstacle"); the rest is outside
/// the field of view.
class LocalMapBuilder {
 public:
  explicit LocalMapBuilder(const LocalMapParams& params = {});

  /// A planar scan from a sensor at `sensor` (robot frame): beam i at heading
  /// sensor.theta + angles[i] with range ranges[i]; ranges >= max_range are "no return" (free
  /// up to max_range, nothing beyond). NaN or negative ranges are skipped.
  void add_scan(const Pose2& sensor, const double* angles, const float* ranges, std::size_t n,
                double max_range);

  /// The thesis' height-band method (proposal 2): for each image column, the nearest pixel
  /// whose height above the floor lies in [z_min, z_max] becomes that column's beam end; a
  /// column with no such pixel is free up to camera.max_range. `optical_in_robot` is the
  /// optical frame's pose in the robot frame (z forward, x right, y down), heights are the
  /// robot frame's z. The image must be camera.height x camera.width, CV_32F, 0 = no data.
  void add_depth_band(const cv::Mat& depth, const PinholeCamera& camera,
                      const Pose3& optical_in_robot, double z_min, double z_max);

  OccupancyGrid build() const;
  const LocalMapParams& params() const { return params_; }

 private:
  void mark(const CellIndex& c, std::uint8_t flag);
  LocalMapParams params_;
  OccupancyGrid frame_;  // geometry of L (origin at (-size/2, -size/2))
  std::vector<std::uint8_t> flags_;
};

}  // namespace kiseki
