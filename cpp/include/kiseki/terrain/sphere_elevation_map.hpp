// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace kiseki {

/// The cells of a sphere digital elevation map (S-DEM, paper 003 sec. 4): tilt theta (rows) and
/// scan angle phi (columns) on a regular grid, both ends included. The paper's grid: theta
/// -120..30 deg, phi -90..90 deg, 1 deg cells (151 x 181), ranges below 5 m only.
///
/// Directions: sensor frame x forward, y left, z up; theta < 0 looks down (kiseki.sim's
/// tilting laser explains the choice against eq. 2's printed sign). A range r in cell
/// (theta, phi) is the point (eq. 2, with the printed "y = r sin(theta)" read as sin(phi))
///     x = r cos(theta) cos(phi),  y = r sin(phi),  z = r sin(theta) cos(phi),
/// and a point goes back by eq. 3: r = |p|, theta = atan2(z, x), phi = atan2(y, sqrt(x^2 + z^2)).
struct SphereGrid {
  double theta_min_deg = -120.0;
  double theta_max_deg = 30.0;
  double phi_min_deg = -90.0;
  double phi_max_deg = 90.0;
  double step_deg = 1.0;
  double max_range = 5.0;  ///< ranges at or beyond it are dropped ("only r < 5 m is used")

  /// Throws std::invalid_argument naming the field: non-finite values, a step <= 0, an empty or
  /// inverted range, theta outside -180..180 or phi outside -90..90, max_range <= 0, more than
  /// 10^7 cells.
  void validate() const;
  int rows() const;  ///< theta cells
  int cols() const;  ///< phi cells
  std::size_t cells() const { return static_cast<std::size_t>(rows()) * static_cast<std::size_t>(cols()); }
  double theta(int row) const;  ///< the cell's centre (rad)
  double phi(int col) const;    ///< the cell's centre (rad)
  /// The cell a direction falls in (nearest centre), or -1 when it is outside the grid.
  long cell_of(double theta, double phi) const;
};

/// r(theta, phi): one range per cell, NaN where the cell has no data.
class SphereElevationMap {
 public:
  explicit SphereElevationMap(const SphereGrid& grid);

  /// From a rows x cols array of ranges (row-major, theta by phi); ranges that are not finite,
  /// <= 0 or >= max_range become NaN.
  static SphereElevationMap from_ranges(const SphereGrid& grid, const std::vector<double>& ranges);
  /// From points in the sensor frame (eq. 3), each turned first by `attitude` (the gyro's
  /// compensation: the map of a level sensor); several points in one cell keep the nearest
  /// (what the laser would see). Non-finite points throw std::invalid_argument.
  static SphereElevationMap from_points(const SphereGrid& grid, const Eigen::Matrix3Xd& points,
                                        const Eigen::Matrix3d& attitude = Eigen::Matrix3d::Identity());
  /// The cell-wise median of sweeps of one grid (the paper's median of 3 measurements): a cell
  /// with data in fewer than half of them (rounded up) is NaN; an even count averages the middle two.
  static SphereElevationMap median(const std::vector<SphereElevationMap>& sweeps);

  const SphereGrid& grid() const { return grid_; }
  const std::vector<double>& ranges() const { return ranges_; }
  std::vector<double>& ranges() { return ranges_; }
  double range(int row, int col) const { return ranges_[static_cast<std::size_t>(row) * grid_.cols() + col]; }
  std::size_t valid_cells() const;

  /// The points of the cells with data (eq. 2), 3 x n, and their cell indices.
  Eigen::Matrix3Xd to_points(std::vector<long>* cells = nullptr) const;
  /// The same sweep seen by a sensor turned by `rotation`: to points, rotated, back to cells.
  SphereElevationMap rotated(const Eigen::Matrix3d& rotation) const;

 private:
  SphereGrid grid_;
  std::vector<double> ranges_;
};

}  // namespace kiseki
