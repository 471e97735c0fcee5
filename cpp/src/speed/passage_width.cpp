// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/speed/passage_width.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kiseki {

PassageWidth passage_width(const PlanarScan& scan, double heading_in_sensor, double half_band) {
  check_scan(scan);
  if (!std::isfinite(heading_in_sensor)) throw std::invalid_argument("the heading must be finite");
  if (!(std::isfinite(half_band) && half_band > 0)) {
    throw std::invalid_argument("half_band must be a positive number of metres, got " + std::to_string(half_band));
  }
  const double c = std::cos(heading_in_sensor), s = std::sin(heading_in_sensor);
  PassageWidth out{0.0, scan.max_range, scan.max_range};
  for (std::size_t i = 0; i < scan.size; ++i) {
    const double r = scan.ranges[i];
    if (!(r < scan.max_range)) continue;  // no return (or NaN): nothing bounds the passage there
    const double px = r * std::cos(scan.angles[i]), py = r * std::sin(scan.angles[i]);
    const double along = px * c + py * s, across = -px * s + py * c;  // the heading's frame
    // Eq. 2's w is measured perpendicular to the heading (Fig. 3a): only obstacles on the line
    // across the heading through the sensor bound it; one ahead of or behind that line (a wall
    // the robot drives towards) is not a side of the passage.
    if (std::abs(along) > half_band) continue;
    if (across >= 0) {
      out.left = std::min(out.left, across);
    } else {
      out.right = std::min(out.right, -across);
    }
  }
  out.width = out.left + out.right;  // w of eq. 2: left wall to right wall, across the heading
  return out;
}

double width_factor(double w, double w1, double w2, double a) {
  if (!(std::isfinite(w1) && w1 > 0)) throw std::invalid_argument("w1 (the robot's width) must be positive");
  if (!(std::isfinite(w2) && w2 > w1)) {
    throw std::invalid_argument("w2 must exceed w1, got w1 = " + std::to_string(w1) + ", w2 = " + std::to_string(w2));
  }
  if (!(std::isfinite(a) && a > 0)) throw std::invalid_argument("a must be positive, got " + std::to_string(a));
  if (std::isnan(w) || w < 0) throw std::invalid_argument("the passage width must be >= 0, got " + std::to_string(w));
  const double b = w2 - w1;  // eq. 3
  const double z = -a * (w - b);
  // 1 / (1 + e^z) without overflow for large z
  return z > 0 ? std::exp(-z) / (1.0 + std::exp(-z)) : 1.0 / (1.0 + std::exp(z));
}

}  // namespace kiseki
