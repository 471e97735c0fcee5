// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "kiseki/core/pose.hpp"

namespace kiseki {

/// Cell values in the ROS nav_msgs/OccupancyGrid convention.
constexpr std::int8_t kFree = 0;
constexpr std::int8_t kOccupied = 100;
constexpr std::int8_t kUnknown = -1;
/// A known free cell: 0..19 (the free space uniform poses are drawn from).
constexpr bool is_free(std::int8_t value) { return value >= 0 && value < 20; }

/// Integer cell coordinates: x is the column, y the row (row 0 at the origin, as in ROS).
struct CellIndex {
  int x = 0;
  int y = 0;
  bool operator==(const CellIndex& o) const { return x == o.x && y == o.y; }
};

/// A 2-D occupancy grid: int8 cells (0 free ... 100 occupied, -1 unknown), a resolution in
/// metres per cell and the pose of the lower-left corner of cell (0, 0) in the world (the ROS
/// map origin, yaw included). Cells are stored in a CV_8SC1 cv::Mat indexed (row = y, col = x).
class OccupancyGrid {
 public:
  /// A width x height grid filled with one value (in -1..100, else std::invalid_argument; an
  /// int, so that 200 is refused by that check rather than wrapped to int8 by a caller).
  OccupancyGrid(int width, int height, double resolution, const Pose2& origin = {},
                int fill = kUnknown);
  /// Wraps existing cells (CV_8SC1); the matrix buffer is shared, not copied.
  OccupancyGrid(const cv::Mat& cells, double resolution, const Pose2& origin);

  int width() const { return cells_.cols; }
  int height() const { return cells_.rows; }
  double resolution() const { return resolution_; }
  const Pose2& origin() const { return origin_; }
  void set_origin(const Pose2& origin);
  const cv::Mat& cells() const { return cells_; }
  cv::Mat& cells() { return cells_; }

  bool contains(int cx, int cy) const { return cx >= 0 && cy >= 0 && cx < width() && cy < height(); }
  bool contains(const CellIndex& c) const { return contains(c.x, c.y); }
  /// Cell value; throws std::out_of_range outside the grid.
  std::int8_t at(int cx, int cy) const;
  /// Sets a cell; std::invalid_argument for a value outside -1..100.
  void set(int cx, int cy, std::int8_t value);
  /// Unchecked access for hot loops (the caller guarantees contains(cx, cy)).
  std::int8_t value(int cx, int cy) const { return cells_.ptr<std::int8_t>(cy)[cx]; }

  /// World point -> continuous grid coordinates in cell units (cell (i, j) spans [i, i+1)).
  Eigen::Vector2d world_to_grid(const Eigen::Vector2d& world) const;
  /// Continuous grid coordinates -> world point.
  Eigen::Vector2d grid_to_world(const Eigen::Vector2d& grid) const;
  /// The cell containing a world point (may lie outside the grid; check with contains()).
  CellIndex world_to_cell(const Eigen::Vector2d& world) const;
  /// World coordinates of a cell's centre.
  Eigen::Vector2d cell_to_world(int cx, int cy) const;

  /// Deep copy (cells() of the copy owns a new buffer).
  OccupancyGrid clone() const;

 private:
  cv::Mat cells_;
  double resolution_;
  Pose2 origin_;
  double cos_ = 1.0, sin_ = 0.0;
};

}  // namespace kiseki
