// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/angle.hpp"

#include <cmath>

namespace kiseki {

double normalize_angle(double angle) {
  if (!std::isfinite(angle)) return angle;
  const double shifted = angle + kPi;
  // fmod is exact, and returns its argument unchanged when that is smaller than the divisor in
  // magnitude: the call is skipped there (an angle near [-pi, pi), nearly every call) with the
  // same result.
  double wrapped = std::abs(shifted) < 2.0 * kPi ? shifted : std::fmod(shifted, 2.0 * kPi);
  if (wrapped < 0.0) wrapped += 2.0 * kPi;
  return wrapped - kPi;
}

double angle_difference(double a, double b) { return normalize_angle(a - b); }

}  // namespace kiseki
