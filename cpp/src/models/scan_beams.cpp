// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/scan_beams.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace kiseki {

namespace {
constexpr double kHeadingTolerance = 0.02;  // rad (1.1 degrees) of heading error allowed
}  // namespace

void ScanBeams::set(const double* angles, const float* ranges, std::size_t n, double max_range_,
                    int max_beams, bool keep_no_return) {
  if (!(max_range_ > 0.0) || !std::isfinite(max_range_)) {
    throw std::invalid_argument("scan: max_range must be finite and > 0");
  }
  if (max_beams < 0) throw std::invalid_argument("scan: max_beams must be >= 0");
  angle.clear(), cos.clear(), sin.clear(), range.clear(), no_return.clear();
  returns = 0;
  max_range = max_range_;
  std::size_t step = 1;
  if (max_beams > 1 && n > 1) step = std::max<std::size_t>(1, (n - 1) / static_cast<std::size_t>(max_beams - 1));
  if (max_beams == 1) step = n;  // the first beam only
  for (std::size_t i = 0; i < n; i += step) {
    if (!std::isfinite(angles[i])) throw std::invalid_argument("scan: beam angles must be finite");
    const float r = ranges[i];
    if (std::isnan(r) || r <= 0.0f) continue;  // invalid
    const bool none = !(r < max_range);          // +inf or at/after max range: no return
    if (none && !keep_no_return) continue;
    angle.push_back(angles[i]);
    cos.push_back(std::cos(angles[i]));
    sin.push_back(std::sin(angles[i]));
    range.push_back(none ? max_range : static_cast<double>(r));
    no_return.push_back(none);
    returns += !none;
  }
}

double ScanBeams::agreement(const RangeCaster& occupied, const Pose2& sensor, double tolerance,
                            bool skip_intrusion) const {
  // A sensor outside the map, in a wall or in unknown space agrees with nothing: rays from
  // there cross no known wall, and would otherwise all "agree".
  const OccupancyGrid& g = occupied.grid();
  const CellIndex at = g.world_to_cell({sensor.x, sensor.y});
  if (!g.contains(at) || g.value(at.x, at.y) < 0 || g.value(at.x, at.y) >= 20) return 0.0;
  std::size_t used = 0, reached = 0;
  for (std::size_t b = 0; b < range.size(); ++b) {
    if (no_return[b]) continue;
    const double heading = sensor.theta + angle[b];
    // The tolerance grows with the range by kHeadingTolerance: a heading error of a degree
    // moves a 30 m beam's end by half a metre.
    const double tol = tolerance + kHeadingTolerance * range[b];
    const double want = range[b] - tol;
    const bool through = want > 0.0 && occupied.range(sensor.x, sensor.y, heading, want) < want;
    if (through) {
      ++used;
      continue;
    }
    const double ex = sensor.x + range[b] * std::cos(heading), ey = sensor.y + range[b] * std::sin(heading);
    const bool at_wall = occupied.clearance(ex, ey) <= tol + g.resolution();
    if (at_wall || !skip_intrusion) ++used;
    if (at_wall) ++reached;
  }
  return used == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(reached) / used;
}

}  // namespace kiseki
