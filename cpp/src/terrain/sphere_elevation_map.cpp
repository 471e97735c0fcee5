// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/sphere_elevation_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kiseki/core/angle.hpp"

namespace kiseki {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMaxCells = 10'000'000;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("SphereGrid: " + message);
}

int count(double low, double high, double step) {
  return static_cast<int>(std::floor((high - low) / step + 1e-9)) + 1;
}

}  // namespace

void SphereGrid::validate() const {
  for (const auto& [name, v] : {std::pair{"theta_min_deg", theta_min_deg}, {"theta_max_deg", theta_max_deg},
                                {"phi_min_deg", phi_min_deg}, {"phi_max_deg", phi_max_deg},
                                {"step_deg", step_deg}, {"max_range", max_range}}) {
    require(std::isfinite(v), std::string(name) + " must be finite, got " + std::to_string(v));
  }
  require(step_deg > 0, "step_deg must be > 0, got " + std::to_string(step_deg));
  require(max_range > 0, "max_range must be > 0, got " + std::to_string(max_range));
  require(theta_min_deg < theta_max_deg, "theta_min_deg must be below theta_max_deg");
  require(phi_min_deg < phi_max_deg, "phi_min_deg must be below phi_max_deg");
  require(theta_min_deg >= -180.0 && theta_max_deg <= 180.0, "theta must lie in -180..180 deg");
  require(phi_min_deg >= -90.0 && phi_max_deg <= 90.0, "phi must lie in -90..90 deg");
  const double cells = (std::floor((theta_max_deg - theta_min_deg) / step_deg) + 1.0) *
                       (std::floor((phi_max_deg - phi_min_deg) / step_deg) + 1.0);
  require(cells <= static_cast<double>(kMaxCells),
          "more than " + std::to_string(kMaxCells) + " cells (step_deg too small)");
}

int SphereGrid::rows() const { return count(theta_min_deg, theta_max_deg, step_deg); }
int SphereGrid::cols() const { return count(phi_min_deg, phi_max_deg, step_deg); }
double SphereGrid::theta(int row) const { return (theta_min_deg + row * step_deg) * kDegree; }
double SphereGrid::phi(int col) const { return (phi_min_deg + col * step_deg) * kDegree; }

long SphereGrid::cell_of(double theta, double phi) const {
  const double step = step_deg * kDegree;
  const double r = std::floor((theta - theta_min_deg * kDegree) / step + 0.5);
  const double c = std::floor((phi - phi_min_deg * kDegree) / step + 0.5);
  if (!(r >= 0 && r < rows() && c >= 0 && c < cols())) return -1;
  return static_cast<long>(r) * cols() + static_cast<long>(c);
}

SphereElevationMap::SphereElevationMap(const SphereGrid& grid) : grid_(grid) {
  grid_.validate();
  ranges_.assign(grid_.cells(), kNaN);
}

SphereElevationMap SphereElevationMap::from_ranges(const SphereGrid& grid, const std::vector<double>& ranges) {
  SphereElevationMap map(grid);
  if (ranges.size() != map.ranges_.size()) {
    throw std::invalid_argument("S-DEM ranges: expected " + std::to_string(map.grid_.rows()) + " x " +
                                std::to_string(map.grid_.cols()) + " values, got " + std::to_string(ranges.size()));
  }
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    const double r = ranges[i];
    map.ranges_[i] = (std::isfinite(r) && r > 0 && r < grid.max_range) ? r : kNaN;
  }
  return map;
}

SphereElevationMap SphereElevationMap::from_points(const SphereGrid& grid, const Eigen::Matrix3Xd& points,
                                                   const Eigen::Matrix3d& attitude) {
  if (!attitude.allFinite()) throw std::invalid_argument("S-DEM attitude: contains NaN or infinite values");
  const Eigen::Matrix3d should_be_identity = attitude.transpose() * attitude;
  if (!should_be_identity.isIdentity(1e-6) || attitude.determinant() < 0) {
    throw std::invalid_argument("S-DEM attitude: not a rotation matrix");
  }
  if (!points.allFinite()) throw std::invalid_argument("S-DEM points: contain NaN or infinite values");
  SphereElevationMap map(grid);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = attitude * points.col(i);
    const double r = p.norm();
    if (!(r > 0 && r < grid.max_range)) continue;
    const long cell = map.grid_.cell_of(std::atan2(p.z(), p.x()), std::atan2(p.y(), std::hypot(p.x(), p.z())));
    if (cell < 0) continue;
    double& slot = map.ranges_[static_cast<std::size_t>(cell)];
    if (!(slot <= r)) slot = r;  // NaN or farther: the nearest point is what the laser sees
  }
  return map;
}

SphereElevationMap SphereElevationMap::median(const std::vector<SphereElevationMap>& sweeps) {
  if (sweeps.empty()) throw std::invalid_argument("S-DEM median: no sweeps");
  const SphereGrid& g = sweeps.front().grid_;
  for (const auto& s : sweeps) {
    if (s.ranges_.size() != sweeps.front().ranges_.size() || s.grid_.step_deg != g.step_deg ||
        s.grid_.theta_min_deg != g.theta_min_deg || s.grid_.phi_min_deg != g.phi_min_deg) {
      throw std::invalid_argument("S-DEM median: the sweeps' grids differ");
    }
  }
  SphereElevationMap out(g);
  const std::size_t need = (sweeps.size() + 1) / 2;
  std::vector<double> values;
  values.reserve(sweeps.size());
  for (std::size_t i = 0; i < out.ranges_.size(); ++i) {
    values.clear();
    for (const auto& s : sweeps) {
      if (!std::isnan(s.ranges_[i])) values.push_back(s.ranges_[i]);
    }
    if (values.size() < need || values.empty()) continue;
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    out.ranges_[i] = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  }
  return out;
}

std::size_t SphereElevationMap::valid_cells() const {
  return static_cast<std::size_t>(
      std::count_if(ranges_.begin(), ranges_.end(), [](double r) { return !std::isnan(r); }));
}

Eigen::Matrix3Xd SphereElevationMap::to_points(std::vector<long>* cells) const {
  Eigen::Matrix3Xd points(3, static_cast<Eigen::Index>(valid_cells()));
  if (cells) cells->clear();
  Eigen::Index k = 0;
  const int cols = grid_.cols();
  for (int row = 0; row < grid_.rows(); ++row) {
    const double th = grid_.theta(row);
    for (int col = 0; col < cols; ++col) {
      const double r = ranges_[static_cast<std::size_t>(row) * cols + col];
      if (std::isnan(r)) continue;
      const double ph = grid_.phi(col);
      points.col(k++) = Eigen::Vector3d(r * std::cos(th) * std::cos(ph), r * std::sin(ph),
                                        r * std::sin(th) * std::cos(ph));  // eq. 2
      if (cells) cells->push_back(static_cast<long>(row) * cols + col);
    }
  }
  return points;
}

SphereElevationMap SphereElevationMap::rotated(const Eigen::Matrix3d& rotation) const {
  return from_points(grid_, to_points(), rotation);
}

}  // namespace kiseki
