// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// Scenes shared by the filters' tests: a small room without symmetry, a scan's angles and a scan
// cast in it.
#pragma once

#include <cmath>
#include <vector>

#include "kiseki/core/angle.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/ray_casting.hpp"

namespace kiseki::test {

// A 10 m x 6 m room (0.05 m cells) with walls, an L-shaped block and a pillar: no symmetry.
inline OccupancyGrid room() {
  OccupancyGrid g(200, 120, 0.05, Pose2(-1.0, -0.5, 0.0), kFree);
  for (int x = 0; x < 200; ++x) g.set(x, 0, kOccupied), g.set(x, 119, kOccupied);
  for (int y = 0; y < 120; ++y) g.set(0, y, kOccupied), g.set(199, y, kOccupied);
  for (int x = 40; x < 90; ++x) g.set(x, 40, kOccupied);
  for (int y = 40; y < 80; ++y) g.set(89, y, kOccupied);
  for (int x = 140; x < 150; ++x)
    for (int y = 70; y < 80; ++y) g.set(x, y, kOccupied);
  for (int x = 160; x < 199; ++x)
    for (int y = 0; y < 10; ++y) g.set(x, y, kUnknown);
  return g;
}

inline std::vector<double> scan_angles(int n) {
  std::vector<double> a(n);
  for (int i = 0; i < n; ++i) a[i] = -kPi / 2 + kPi * i / (n - 1);
  return a;
}

inline std::vector<float> cast(const OccupancyGrid& g, const Pose2& sensor, const std::vector<double>& angles, double max_range) {
  RayCastOptions o;
  o.max_range = max_range;
  std::vector<double> r(angles.size());
  cast_scan(g, sensor, angles.data(), angles.size(), o, r.data());
  return std::vector<float>(r.begin(), r.end());
}

// The distance between two poses' positions (m).
inline double position_error(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

}  // namespace kiseki::test
