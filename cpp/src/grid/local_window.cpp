// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/local_window.hpp"

#include <cmath>
#include <stdexcept>

namespace kiseki {

OccupancyGrid extract_window(const OccupancyGrid& map, const Pose2& center, double width,
                             double height, double resolution) {
  if (!(width > 0.0) || !(height > 0.0) || !std::isfinite(width) || !std::isfinite(height)) {
    throw std::invalid_argument("extract_window: width and height must be positive and finite");
  }
  if (!std::isfinite(center.x) || !std::isfinite(center.y) || !std::isfinite(center.theta)) {
    throw std::invalid_argument("extract_window: pose must be finite");
  }
  if (!(resolution >= 0.0) || !std::isfinite(resolution)) {  // -0.1 and NaN took the map's
    throw std::invalid_argument("extract_window: resolution must be 0 (the map's) or finite and > 0");
  }
  const double res = resolution > 0.0 ? resolution : map.resolution();
  const int cols = static_cast<int>(std::lround(width / res));
  const int rows = static_cast<int>(std::lround(height / res));
  if (cols < 1 || rows < 1 || static_cast<double>(cols) * rows > 1e8) {
    throw std::invalid_argument("extract_window: window must span between 1 and 1e8 cells");
  }
  const Pose2 origin = center.compose(Pose2(-0.5 * cols * res, -0.5 * rows * res, 0.0));
  OccupancyGrid window(cols, rows, res, origin, kUnknown);
  // The map-grid coordinates of window cell (i, j)'s centre are affine in (i, j).
  const Eigen::Vector2d g00 = map.world_to_grid(window.cell_to_world(0, 0));
  const Eigen::Vector2d gx = map.world_to_grid(window.cell_to_world(1, 0)) - g00;
  const Eigen::Vector2d gy = map.world_to_grid(window.cell_to_world(0, 1)) - g00;
  for (int j = 0; j < rows; ++j) {
    auto* out = window.cells().ptr<std::int8_t>(j);
    Eigen::Vector2d g = g00 + j * gy;
    for (int i = 0; i < cols; ++i, g += gx) {
      if (std::abs(g.x()) > 1e9 || std::abs(g.y()) > 1e9) continue;  // far outside: unknown
      const int mx = static_cast<int>(std::floor(g.x()));
      const int my = static_cast<int>(std::floor(g.y()));
      if (map.contains(mx, my)) out[i] = map.value(mx, my);
    }
  }
  return window;
}

}  // namespace kiseki
