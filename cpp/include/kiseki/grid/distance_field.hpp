// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// Euclidean distance (metres) from every cell centre to the centre of the nearest cell whose
/// value is >= occupied_threshold, computed with OpenCV's exact distance transform
/// (cv::distanceTransform, DIST_L2, DIST_MASK_PRECISE). Unknown cells count as non-obstacles.
/// Returns a CV_32FC1 matrix of the grid's size; +inf everywhere when the grid has no obstacle.
cv::Mat distance_field(const OccupancyGrid& grid, std::int8_t occupied_threshold = 65);

}  // namespace kiseki
