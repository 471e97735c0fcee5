// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kiseki {
namespace {

void check_resolution(double resolution) {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw std::invalid_argument("OccupancyGrid: resolution must be a positive finite number, got " +
                                std::to_string(resolution));
  }
}

void check_origin(const Pose2& o) {
  if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.theta)) {
    throw std::invalid_argument("OccupancyGrid: origin must be finite");
  }
}

void check_cell_value(int v) {
  if (v < kUnknown || v > kOccupied) {
    throw std::invalid_argument(
        "OccupancyGrid: cell values must lie in -1..100 (-1 unknown, 0 free, 100 occupied), got " +
        std::to_string(v));
  }
}

}  // namespace

OccupancyGrid::OccupancyGrid(int width, int height, double resolution, const Pose2& origin,
                             int fill)
    : resolution_(resolution) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("OccupancyGrid: width and height must be positive, got " +
                                std::to_string(width) + " x " + std::to_string(height));
  }
  if (static_cast<double>(width) * height > 1e9) {
    throw std::invalid_argument("OccupancyGrid: more than 1e9 cells requested");
  }
  check_resolution(resolution);
  check_cell_value(fill);
  cells_ = cv::Mat(height, width, CV_8SC1, cv::Scalar(fill));
  set_origin(origin);
}

OccupancyGrid::OccupancyGrid(const cv::Mat& cells, double resolution, const Pose2& origin)
    : cells_(cells), resolution_(resolution) {
  if (cells.type() != CV_8SC1 || cells.dims != 2 || cells.empty()) {
    throw std::invalid_argument("OccupancyGrid: cells must be a non-empty 2-D int8 matrix");
  }
  check_resolution(resolution);
  set_origin(origin);
}

void OccupancyGrid::set_origin(const Pose2& origin) {
  check_origin(origin);
  origin_ = origin;
  cos_ = std::cos(origin.theta);
  sin_ = std::sin(origin.theta);
}

std::int8_t OccupancyGrid::at(int cx, int cy) const {
  if (!contains(cx, cy)) {
    throw std::out_of_range("OccupancyGrid: cell (" + std::to_string(cx) + ", " +
                            std::to_string(cy) + ") is outside the " + std::to_string(width()) +
                            " x " + std::to_string(height()) + " grid");
  }
  return value(cx, cy);
}

void OccupancyGrid::set(int cx, int cy, std::int8_t v) {
  at(cx, cy);  // bounds check
  check_cell_value(v);
  cells_.ptr<std::int8_t>(cy)[cx] = v;
}

Eigen::Vector2d OccupancyGrid::world_to_grid(const Eigen::Vector2d& world) const {
  const double dx = world.x() - origin_.x, dy = world.y() - origin_.y;
  return {(cos_ * dx + sin_ * dy) / resolution_, (-sin_ * dx + cos_ * dy) / resolution_};
}

Eigen::Vector2d OccupancyGrid::grid_to_world(const Eigen::Vector2d& g) const {
  const double gx = g.x() * resolution_, gy = g.y() * resolution_;
  return {origin_.x + cos_ * gx - sin_ * gy, origin_.y + sin_ * gx + cos_ * gy};
}

CellIndex OccupancyGrid::world_to_cell(const Eigen::Vector2d& world) const {
  const Eigen::Vector2d g = world_to_grid(world);
  if (!std::isfinite(g.x()) || !std::isfinite(g.y())) {
    throw std::invalid_argument("OccupancyGrid: world point must be finite");
  }
  // Clamp before the cast: far-away points must not overflow int.
  const double lim = 1e9;
  return {static_cast<int>(std::floor(std::clamp(g.x(), -lim, lim))),
          static_cast<int>(std::floor(std::clamp(g.y(), -lim, lim)))};
}

Eigen::Vector2d OccupancyGrid::cell_to_world(int cx, int cy) const {
  return grid_to_world({cx + 0.5, cy + 0.5});
}

OccupancyGrid OccupancyGrid::clone() const { return {cells_.clone(), resolution_, origin_}; }

}  // namespace kiseki
