// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// A scene shared by the rubble tests: a floor with mounds, as a sensor 0.5 m above it sees it.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <random>

namespace kiseki::test {

constexpr double kDeg = M_PI / 180.0;

/// A floor 0.5 m below the sensor with smooth mounds, sampled densely.
inline Eigen::Matrix3Xd mound_floor(unsigned seed, int n = 20000) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-2.5, 3.5), uy(-3.0, 3.0);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) {
    const double x = ux(rng), y = uy(rng);
    p.col(i) << x, y, -0.5 + 0.25 * std::exp(-((x - 1.2) * (x - 1.2) + (y - 0.8) * (y - 0.8)) / 0.3) +
                          0.15 * std::exp(-((x - 2.0) * (x - 2.0) + (y + 1.1) * (y + 1.1)) / 0.2) +
                          0.05 * std::sin(2.0 * x) * std::cos(1.5 * y);
  }
  return p;
}

}  // namespace kiseki::test
