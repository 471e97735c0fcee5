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
  /// up to max_range, nothing beyond). No reading is no information: NaN, infinite, zero and
  /// negative ranges add nothing.
  void add_scan(const Pose2& sensor, const double* angles, const float* ranges, std::size_t n,
                double max_range);

  /// The thesis' height-band method (proposal 2; with a thin band, its fixed-height plane):
  /// each image column is one beam at the column's heading.
  /// - A reading is a depth in [camera.min_range, camera.max_range); +inf is the camera
  ///   reporting "nothing within range" (REP 117) and is a ray to max_range without an end.
  ///   0, NaN, -inf and depths outside the range are no reading: they say nothing, so a column
  ///   whose pixels are all no reading adds no cell, free or occupied (a bench under the 0.5 m
  ///   minimum range hides what lies behind it; it does not open a free ray through it).
  /// - A pixel sees the band where its footprint, between its top and bottom edge rays,
  ///   overlaps [z_min, z_max] (robot-frame heights; z_min == z_max is a plane: the pixels
  ///   whose footprint holds it). The nearest reading that lies in the band is the column's
  ///   beam end (the thesis: the pixel with the smallest depth); the cells before it are free,
  ///   those behind it occupied.
  /// - A column without a reading in the band is free only as far as some pixel's ray ran
  ///   inside the band before it left it (the thesis: a cell is free where a beam passed; a ray
  ///   that dips under the band at 1 m says nothing about the band at 5 m); beyond that it adds
  ///   nothing, and no cell of it is occupied. The free stretch is the hull of the pixels'
  ///   in-band stretches (their union when the camera itself is in the band, as mounted).
  /// `optical_in_robot` is the optical frame's pose in the robot frame (z forward, x right,
  /// y down). The image must be camera.height x camera.width, CV_32F.
  void add_depth_band(const cv::Mat& depth, const PinholeCamera& camera,
                      const Pose3& optical_in_robot, double z_min, double z_max);

  OccupancyGrid build() const;
  /// The cells a beam ended in (CV_8U, 1 = a hit), of build()'s size: what build() marks
  /// occupied minus the space behind the hits (for EvidenceMap).
  cv::Mat hits() const;
  const LocalMapParams& params() const { return params_; }

 private:
  void mark(const CellIndex& c, std::uint8_t flag);
  /// One beam from `start` at `heading`: cells from `free_from` (metres along the beam) up to
  /// `range` are passed; with `hit` the cell holding the end is the hit and the cells after it
  /// on the ray are hidden, without it nothing beyond `range` is marked.
  void add_beam(const Eigen::Vector2d& start, double heading, double free_from, double range,
                bool hit);
  LocalMapParams params_;
  OccupancyGrid frame_;  // geometry of L (origin at (-size/2, -size/2))
  std::vector<std::uint8_t> flags_;
};

}  // namespace kiseki
