// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// What stops a ray.
struct RayCastOptions {
  double max_range = 30.0;              ///< metres; a ray that hits nothing returns this
  std::int8_t occupied_threshold = 65;  ///< cells with value >= this stop the ray (ROS 0.65)
  bool unknown_is_obstacle = false;     ///< whether unknown (-1) cells stop the ray
};

/// Result of one ray: distance to the boundary of the first obstacle cell entered (or
/// max_range), and whether an obstacle was hit.
struct RayHit {
  double range = 0.0;
  bool hit = false;
  CellIndex cell;  ///< the obstacle cell when hit
};

/// Clips the segment p + t d, t in [t0, t1], to the box [0, w] x [0, h] (slab method), in grid
/// cell units; returns false when the segment misses the box. Shared by the ray casters.
bool clip_to_box(const Eigen::Vector2d& p, const Eigen::Vector2d& d, double w, double h,
                 double& t0, double& t1);

/// Casts one ray from a world point along a world heading with the grid traversal of
/// Amanatides and Woo (1987): the exact sequence of cells the ray crosses. The part of the ray
/// outside the grid crosses no obstacle. A ray starting inside an obstacle has range 0.
RayHit cast_ray(const OccupancyGrid& grid, const Eigen::Vector2d& start, double heading,
                const RayCastOptions& options);

/// The cells a ray crosses inside the grid, in order, up to and including the first obstacle
/// cell, or until max_range.
std::vector<CellIndex> cells_on_ray(const OccupancyGrid& grid, const Eigen::Vector2d& start,
                                    double heading, const RayCastOptions& options);

/// Casts a whole scan: beam i leaves the sensor pose at heading pose.theta + angles[i].
/// Writes n ranges to out.
void cast_scan(const OccupancyGrid& grid, const Pose2& sensor_pose, const double* angles,
               std::size_t n, const RayCastOptions& options, double* out);

}  // namespace kiseki
