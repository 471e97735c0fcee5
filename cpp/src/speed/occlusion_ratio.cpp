// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/speed/occlusion_ratio.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kiseki/core/angle.hpp"

namespace kiseki {

namespace {

/// The beam whose wedge holds the bearing beta (sensor frame), or -1 outside the field of view.
/// Beam i's wedge reaches halfway to each neighbour; the end beams reach as far outwards.
long beam_of(const PlanarScan& scan, double beta) {
  const double* a = scan.angles;
  const std::size_t n = scan.size;
  if (n == 1) return std::abs(normalize_angle(beta - a[0])) <= 1e-12 ? 0 : -1;
  const double first_half = 0.5 * (a[1] - a[0]), last_half = 0.5 * (a[n - 1] - a[n - 2]);
  if (beta < a[0] - first_half || beta > a[n - 1] + last_half) return -1;
  const std::size_t hi = static_cast<std::size_t>(std::lower_bound(a, a + n, beta) - a);
  if (hi == 0) return 0;
  if (hi == n) return static_cast<long>(n - 1);
  return static_cast<long>(beta - a[hi - 1] <= a[hi] - beta ? hi - 1 : hi);
}

}  // namespace

void check_scan(const PlanarScan& scan) {
  if (scan.size == 0) throw std::invalid_argument("the scan is empty (no beams)");
  if (!(std::isfinite(scan.max_range) && scan.max_range > 0)) {
    throw std::invalid_argument("max_range must be a positive number of metres, got " +
                                std::to_string(scan.max_range));
  }
  for (std::size_t i = 0; i < scan.size; ++i) {
    if (!std::isfinite(scan.angles[i])) throw std::invalid_argument("beam angles must be finite");
    if (i > 0 && !(scan.angles[i] > scan.angles[i - 1])) {
      throw std::invalid_argument("beam angles must increase strictly (beam " + std::to_string(i) + ")");
    }
    if (scan.ranges[i] < 0) throw std::invalid_argument("ranges must not be negative (beam " + std::to_string(i) + ")");
  }
  if (scan.angles[scan.size - 1] - scan.angles[0] > 2 * kPi + 1e-9) {
    throw std::invalid_argument("beam angles span more than a full turn");
  }
}

OcclusionRatio occlusion_ratio(const OccupancyGrid& map, const Pose2& sensor_pose, const PlanarScan& scan,
                               double heading, const OcclusionRatioOptions& options, cv::Mat* labels) {
  check_scan(scan);
  if (!(options.half_angle > 0 && options.half_angle <= kPi)) {
    throw std::invalid_argument("half_angle must be in (0, pi] rad, got " + std::to_string(options.half_angle));
  }
  if (!std::isfinite(heading) || !std::isfinite(sensor_pose.x) || !std::isfinite(sensor_pose.y) ||
      !std::isfinite(sensor_pose.theta)) {
    throw std::invalid_argument("the sensor pose and the heading must be finite");
  }
  const double range = scan.max_range, res = map.resolution();
  const double hx = std::cos(heading), hy = std::sin(heading), cos_half = std::cos(options.half_angle);
  // The disc of radius max_range around the sensor, as a box of cells (the map may be rotated).
  const Eigen::Vector2d centre = map.world_to_grid({sensor_pose.x, sensor_pose.y});
  const double radius_cells = range / res + 1.0;
  const int x0 = std::max(0, static_cast<int>(std::floor(centre.x() - radius_cells)));
  const int y0 = std::max(0, static_cast<int>(std::floor(centre.y() - radius_cells)));
  const int x1 = std::min(map.width() - 1, static_cast<int>(std::ceil(centre.x() + radius_cells)));
  const int y1 = std::min(map.height() - 1, static_cast<int>(std::ceil(centre.y() + radius_cells)));
  // Cell centres step by (res cos yaw, res sin yaw) along a row and (-res sin yaw, res cos yaw)
  // across rows (the map's origin may be rotated).
  const Eigen::Vector2d origin = map.cell_to_world(x0, y0);
  const Eigen::Vector2d along_row = map.cell_to_world(x0 + 1, y0) - origin;
  const Eigen::Vector2d across_rows = map.cell_to_world(x0, y0 + 1) - origin;
  const double cs = std::cos(sensor_pose.theta), ss = std::sin(sensor_pose.theta);
  const double range2 = range * range, cell_margin = 0.5 * res;
  if (labels != nullptr) *labels = cv::Mat::zeros(map.height(), map.width(), CV_8UC1);
  OcclusionRatio out;
  for (int cy = y0; cy <= y1; ++cy) {
    const auto* row = map.cells().ptr<std::int8_t>(cy);
    const Eigen::Vector2d first = origin + (cy - y0) * across_rows;
    auto* label = labels != nullptr ? labels->ptr<std::uint8_t>(cy) : nullptr;
    for (int cx = x0; cx <= x1; ++cx) {
      const std::int8_t v = row[cx];
      if (v < 0 || v > options.free_threshold) continue;  // R_map_free
      const double dx = first.x() + (cx - x0) * along_row.x() - sensor_pose.x;
      const double dy = first.y() + (cx - x0) * along_row.y() - sensor_pose.y;
      const double rho2 = dx * dx + dy * dy;
      if (rho2 > range2) continue;  // R_sensor: within reach ...
      const double rho = std::sqrt(rho2);
      if (rho < 1e-9) {  // the sensor's own cell
        ++out.free_cells, ++out.seen_cells;
        if (label != nullptr) label[cx] = 2;
        continue;
      }
      if (dx * hx + dy * hy < rho * cos_half) continue;  // ... and within +-theta of the heading
      ++out.free_cells;
      if (label != nullptr) label[cx] = 1;
      // the bearing in the sensor frame, in (-pi, pi]
      const long beam = beam_of(scan, std::atan2(-dx * ss + dy * cs, dx * cs + dy * ss));
      if (beam < 0) continue;
      const double r = scan.ranges[beam];
      if (std::isnan(r)) continue;
      if (r >= range || rho <= r - cell_margin) {  // R_recognize
        ++out.seen_cells;
        if (label != nullptr) label[cx] = 2;
      }
    }
  }
  out.ratio = out.free_cells == 0 ? 1.0 : static_cast<double>(out.seen_cells) / static_cast<double>(out.free_cells);
  return out;
}

}  // namespace kiseki
