// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include "kiseki/speed/occlusion_ratio.hpp"

namespace kiseki {

/// The width of the passage across the direction of motion (the paper's Fig. 3a): in a frame
/// whose x axis is the heading, the scan's hit points with 0 <= x <= window_ahead bound the
/// passage on the left (y > 0) and on the right (y < 0); w = the nearest left |y| + the nearest
/// right |y|. A side without such a point is open: its distance counts as max_range.
struct PassageWidth {
  double width = 0.0;  ///< w (m)
  double left = 0.0;   ///< distance to the nearest obstacle on the left (m)
  double right = 0.0;  ///< ... on the right (m)
};

/// heading_in_sensor: the direction of motion relative to the sensor's x axis (rad).
PassageWidth passage_width(const PlanarScan& scan, double heading_in_sensor, double window_ahead);

/// Eq. 3 with the paper's typo corrected (it prints 1 / (1 - exp(...)), which has a pole at
/// w = b and is negative below it): the sigmoid f(w) = 1 / (1 + exp(-a (w - b))), b = w2 - w1,
/// w1 the robot's width, w2 the width that needs no slowing down. Throws std::invalid_argument
/// unless w2 > w1 > 0 and a > 0.
double width_factor(double w, double w1, double w2, double a);

}  // namespace kiseki
