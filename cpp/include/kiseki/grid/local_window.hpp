// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// Extracts a width x height (metres) window of the grid centred on a pose and aligned with
/// it: the returned grid's x axis is the pose's heading and its origin is the window's
/// lower-left corner (pose (+) (-width/2, -height/2, 0)). Each window cell takes the value of
/// the map cell under its centre (nearest neighbour); cells outside the map are unknown.
/// resolution <= 0 means the map's resolution.
OccupancyGrid extract_window(const OccupancyGrid& map, const Pose2& center, double width,
                             double height, double resolution = 0.0);

}  // namespace kiseki
