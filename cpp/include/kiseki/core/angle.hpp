// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

namespace kiseki {

constexpr double kPi = 3.14159265358979323846;
/// One degree in radians.
constexpr double kDegree = kPi / 180.0;

/// Wraps an angle to [-pi, pi).
double normalize_angle(double angle);

/// Smallest signed difference a - b, wrapped to [-pi, pi).
double angle_difference(double a, double b);

}  // namespace kiseki
