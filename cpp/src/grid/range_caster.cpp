// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/range_caster.hpp"

#include "kiseki/grid/ray_casting.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace kiseki {

RangeCaster::RangeCaster(const OccupancyGrid& grid, bool unknown_stops, std::int8_t occupied_threshold)
    : grid_(grid.clone()), unknown_stops_(unknown_stops), threshold_(occupied_threshold) {
  cv::Mat mask(grid_.height(), grid_.width(), CV_8UC1);
  int stopping = 0;
  for (int y = 0; y < grid_.height(); ++y) {
    auto* dst = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < grid_.width(); ++x) {
      const bool s = stops(x, y);
      dst[x] = s ? 0 : 255;
      stopping += s;
    }
  }
  if (stopping == 0) {
    distance_ = cv::Mat(grid_.height(), grid_.width(), CV_32FC1,
                        cv::Scalar(std::numeric_limits<float>::infinity()));
  } else {
    cv::distanceTransform(mask, distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  }
}

double RangeCaster::clearance(double x, double y) const {
  const CellIndex c = grid_.world_to_cell({x, y});
  if (!grid_.contains(c)) return std::numeric_limits<double>::infinity();
  return static_cast<double>(distance_.ptr<float>(c.y)[c.x]) * grid_.resolution();
}

bool RangeCaster::stops(int cx, int cy) const {
  const std::int8_t v = grid_.value(cx, cy);
  return v >= threshold_ || (unknown_stops_ && v < 0);
}

double RangeCaster::range(double x, double y, double heading, double max_range) const {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(heading) || !(max_range >= 0.0)) {
    throw std::invalid_argument("range caster: start, heading and max_range must be finite");
  }
  const double res = grid_.resolution();
  const Eigen::Vector2d p = grid_.world_to_grid({x, y});
  const double a = heading - grid_.origin().theta;
  const double dx = std::cos(a), dy = std::sin(a);
  double t0 = 0.0, t1 = max_range / res;
  if (!clip_to_box(p, {dx, dy}, grid_.width(), grid_.height(), t0, t1)) return max_range;
  const double inf = std::numeric_limits<double>::infinity();
  const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
  const double dt_x = dx != 0.0 ? std::abs(1.0 / dx) : inf, dt_y = dy != 0.0 ? std::abs(1.0 / dy) : inf;
  constexpr double kSqrt2 = 1.4142135623730951;
  const float* dist = distance_.ptr<float>(0);  // continuous; 0 exactly at stopping cells
  const int w = grid_.width(), h = grid_.height();
  double t = t0;  // where the ray is now (inside cell cx, cy)
  bool jumped = true;
  int cx = 0, cy = 0;
  double next_x = inf, next_y = inf;
  while (true) {
    if (jumped) {  // (re)start the cell walk at t
      cx = std::clamp(static_cast<int>(std::floor(p.x() + t * dx)), 0, grid_.width() - 1);
      cy = std::clamp(static_cast<int>(std::floor(p.y() + t * dy)), 0, grid_.height() - 1);
      next_x = dx != 0.0 ? ((cx + (step_x > 0 ? 1 : 0)) - p.x()) / dx : inf;
      next_y = dy != 0.0 ? ((cy + (step_y > 0 ? 1 : 0)) - p.y()) / dy : inf;
      jumped = false;
    }
    const float d = dist[static_cast<std::ptrdiff_t>(cy) * w + cx];
    if (d == 0.0f) return t * res;  // a stopping cell
    const double clear = static_cast<double>(d) - kSqrt2;
    if (clear > 1.0) {  // free for `clear` cells from anywhere in this cell
      t += clear;
      if (t > t1) return max_range;
      jumped = true;
      continue;
    }
    if (next_x < next_y) {
      t = next_x;
      next_x += dt_x;
      cx += step_x;
    } else {
      t = next_y;
      next_y += dt_y;
      cy += step_y;
    }
    if (t > t1 || cx < 0 || cy < 0 || cx >= w || cy >= h) return max_range;
  }
}

}  // namespace kiseki
