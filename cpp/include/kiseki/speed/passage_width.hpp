// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include "kiseki/speed/occlusion_ratio.hpp"

namespace kiseki {

/// The width w of the passage, eq. 2 of Yorozu, Moriguchi and Takahashi: "the distance between
/// the obstacles detected, perpendicular to the robot's direction of motion" (Fig. 3a). In a
/// frame whose x axis is the heading and whose origin is the sensor, the line across the heading
/// (x = 0) is where w is measured: the scan's hit points with |x| <= half_band (a strip that
/// holds a beam or more of a discrete scan) bound the passage on the left (y > 0) and on the
/// right (y < 0); w = the nearest left |y| + the nearest right |y|. An obstacle ahead of the
/// strip (a wall the robot drives towards) is not a side of the passage and leaves w alone. A
/// side without such a point (an open side, or one outside the scan's field of view) counts
/// max_range.
struct PassageWidth {
  double width = 0.0;  ///< w (m)
  double left = 0.0;   ///< distance to the nearest obstacle on the left (m)
  double right = 0.0;  ///< ... on the right (m)
};

/// heading_in_sensor: the direction of motion relative to the sensor's x axis (rad).
/// half_band: half the strip's width along the heading (m), > 0.
PassageWidth passage_width(const PlanarScan& scan, double heading_in_sensor, double half_band);

/// Eq. 3 with the paper's typo corrected (it prints 1 / (1 - exp(...)), which has a pole at
/// w = b and is negative below it): the sigmoid f(w) = 1 / (1 + exp(-a (w - b))), b = w2 - w1,
/// w1 the robot's width, w2 the width that needs no slowing down. Throws std::invalid_argument
/// unless w2 > w1 > 0 and a > 0.
double width_factor(double w, double w1, double w2, double a);

}  // namespace kiseki
