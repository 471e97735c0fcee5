// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/angle.hpp"

#include <cmath>

namespace kiseki {

double normalize_angle(double angle) {
  if (!std::isfinite(angle)) return angle;
  double wrapped = std::fmod(angle + kPi, 2.0 * kPi);
  if (wrapped < 0.0) wrapped += 2.0 * kPi;
  return wrapped - kPi;
}

double angle_difference(double a, double b) { return normalize_angle(a - b); }

}  // namespace kiseki
