// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/distance_field.hpp"

#include <limits>
#include <opencv2/imgproc.hpp>

namespace kiseki {

cv::Mat distance_field(const OccupancyGrid& grid, std::int8_t occupied_threshold) {
  // distanceTransform measures the distance to the nearest zero pixel: obstacles become 0.
  cv::Mat free_mask(grid.height(), grid.width(), CV_8UC1);
  int obstacles = 0;
  for (int y = 0; y < grid.height(); ++y) {
    const auto* src = grid.cells().ptr<std::int8_t>(y);
    auto* dst = free_mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < grid.width(); ++x) {
      const bool obstacle = src[x] >= occupied_threshold;
      dst[x] = obstacle ? 0 : 255;
      obstacles += obstacle;
    }
  }
  cv::Mat distance;
  if (obstacles == 0) {
    distance = cv::Mat(grid.height(), grid.width(), CV_32FC1,
                       cv::Scalar(std::numeric_limits<float>::infinity()));
    return distance;
  }
  cv::distanceTransform(free_mask, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  distance *= grid.resolution();
  return distance;
}

}  // namespace kiseki
