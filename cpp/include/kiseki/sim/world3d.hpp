// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstddef>

namespace kiseki {

/// Anything a 3-D range sensor can be simulated in: a ray from `origin` along the unit vector
/// `direction` returns the distance to the first surface, or max_range when nothing is hit.
class World3D {
 public:
  virtual ~World3D() = default;
  virtual double cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                      double max_range) const = 0;
  /// Axis-aligned bounds of the world's geometry: {min, max}.
  virtual Eigen::AlignedBox3d bounds() const = 0;

  /// Casts n rays (origins and unit directions row-major n x 3) into out (n).
  void cast_many(const double* origins, const double* directions, std::size_t n, double max_range,
                 double* out) const;
};

}  // namespace kiseki
