// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/ray_casting.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kiseki {
namespace {

void check_options(const RayCastOptions& o) {
  if (!(o.max_range >= 0.0) || !std::isfinite(o.max_range)) {
    throw std::invalid_argument("ray casting: max_range must be finite and >= 0");
  }
}

// Walks the cells of the ray in grid units. visit(cell, t_enter) returns true to stop.
template <typename Visit>
void traverse(const OccupancyGrid& grid, const Eigen::Vector2d& start, double heading,
              double max_range, Visit&& visit) {
  if (!std::isfinite(start.x()) || !std::isfinite(start.y()) || !std::isfinite(heading)) {
    throw std::invalid_argument("ray casting: start and heading must be finite");
  }
  const Eigen::Vector2d p = grid.world_to_grid(start);
  const double a = heading - grid.origin().theta;
  const Eigen::Vector2d d(std::cos(a), std::sin(a));
  double t0 = 0.0, t1 = max_range / grid.resolution();
  if (!clip_to_box(p, d, grid.width(), grid.height(), t0, t1)) return;
  const Eigen::Vector2d q = p + t0 * d;
  int cx = std::clamp(static_cast<int>(std::floor(q.x())), 0, grid.width() - 1);
  int cy = std::clamp(static_cast<int>(std::floor(q.y())), 0, grid.height() - 1);
  const double inf = std::numeric_limits<double>::infinity();
  const int step_x = d.x() > 0 ? 1 : -1, step_y = d.y() > 0 ? 1 : -1;
  const double dt_x = d.x() != 0.0 ? std::abs(1.0 / d.x()) : inf;
  const double dt_y = d.y() != 0.0 ? std::abs(1.0 / d.y()) : inf;
  // t at which the ray crosses the next vertical / horizontal cell boundary.
  double next_x = d.x() != 0.0 ? ((cx + (step_x > 0 ? 1 : 0)) - p.x()) / d.x() : inf;
  double next_y = d.y() != 0.0 ? ((cy + (step_y > 0 ? 1 : 0)) - p.y()) / d.y() : inf;
  double t_enter = t0;
  while (true) {
    if (visit(CellIndex{cx, cy}, t_enter)) return;
    if (next_x < next_y) {
      t_enter = next_x;
      next_x += dt_x;
      cx += step_x;
    } else {
      t_enter = next_y;
      next_y += dt_y;
      cy += step_y;
    }
    if (t_enter > t1 || !grid.contains(cx, cy)) return;
  }
}

bool is_obstacle(std::int8_t v, const RayCastOptions& o) {
  return v >= o.occupied_threshold || (o.unknown_is_obstacle && v < 0);
}

}  // namespace

bool clip_to_box(const Eigen::Vector2d& p, const Eigen::Vector2d& d, double w, double h,
                 double& t0, double& t1) {
  const double lo[2] = {0.0, 0.0}, hi[2] = {w, h};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - p[k]) / d[k], tb = (hi[k] - p[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

RayHit cast_ray(const OccupancyGrid& grid, const Eigen::Vector2d& start, double heading,
                const RayCastOptions& options) {
  check_options(options);
  RayHit result{options.max_range, false, {}};
  traverse(grid, start, heading, options.max_range, [&](const CellIndex& c, double t) {
    if (!is_obstacle(grid.value(c.x, c.y), options)) return false;
    result = {std::min(t * grid.resolution(), options.max_range), true, c};
    return true;
  });
  return result;
}

std::vector<CellIndex> cells_on_ray(const OccupancyGrid& grid, const Eigen::Vector2d& start,
                                    double heading, const RayCastOptions& options) {
  check_options(options);
  std::vector<CellIndex> cells;
  traverse(grid, start, heading, options.max_range, [&](const CellIndex& c, double) {
    cells.push_back(c);
    return is_obstacle(grid.value(c.x, c.y), options);
  });
  return cells;
}

void cast_scan(const OccupancyGrid& grid, const Pose2& sensor_pose, const double* angles,
               std::size_t n, const RayCastOptions& options, double* out) {
  check_options(options);
  const Eigen::Vector2d start(sensor_pose.x, sensor_pose.y);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = cast_ray(grid, start, sensor_pose.theta + angles[i], options).range;
  }
}

}  // namespace kiseki
