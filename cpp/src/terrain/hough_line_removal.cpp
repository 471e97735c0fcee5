// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/hough_line_removal.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"

namespace kiseki {

namespace {


void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("Hough line removal: " + message);
}

struct ScanPoint {
  double u, v;
  int col;
  bool alive;
};

/// One tilt scan: finds and removes lines; returns the number found and marks removed points.
int remove_lines_in_scan(std::vector<ScanPoint>& points, const HoughLineParams& p, double max_range) {
  const int angles = static_cast<int>(std::ceil(180.0 / p.angle_step_deg - 1e-9));
  const int rhos = 2 * static_cast<int>(std::ceil(max_range / p.rho_step)) + 1;
  const int rho_offset = rhos / 2;
  std::vector<double> cosines(static_cast<std::size_t>(angles)), sines(static_cast<std::size_t>(angles));
  for (int a = 0; a < angles; ++a) {
    cosines[static_cast<std::size_t>(a)] = std::cos(a * p.angle_step_deg * kDegree);
    sines[static_cast<std::size_t>(a)] = std::sin(a * p.angle_step_deg * kDegree);
  }
  std::vector<int> votes(static_cast<std::size_t>(angles) * rhos);
  const auto bin_of = [&](const ScanPoint& q, int a) {
    const double rho = q.u * cosines[static_cast<std::size_t>(a)] + q.v * sines[static_cast<std::size_t>(a)];
    return static_cast<int>(std::floor(rho / p.rho_step + 0.5)) + rho_offset;
  };
  int found = 0;
  while (found < p.max_lines) {
    std::fill(votes.begin(), votes.end(), 0);
    for (const auto& q : points) {
      if (!q.alive) continue;
      for (int a = 0; a < angles; ++a) {
        const int b = bin_of(q, a);
        if (b >= 0 && b < rhos) ++votes[static_cast<std::size_t>(a) * rhos + b];
      }
    }
    const auto top = std::max_element(votes.begin(), votes.end());  // ties: the first bin
    if (static_cast<std::size_t>(*top) < p.min_votes) break;
    const auto k = static_cast<std::size_t>(top - votes.begin());
    const int a = static_cast<int>(k / rhos), b = static_cast<int>(k % rhos);
    // Total least squares on the bin's points: the line through their mean along the principal axis.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    std::size_t n = 0;
    for (const auto& q : points) {
      if (q.alive && bin_of(q, a) == b) {
        mean += Eigen::Vector2d(q.u, q.v);
        ++n;
      }
    }
    mean /= static_cast<double>(n);
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const auto& q : points) {
      if (q.alive && bin_of(q, a) == b) {
        const Eigen::Vector2d d = Eigen::Vector2d(q.u, q.v) - mean;
        scatter += d * d.transpose();
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    const Eigen::Vector2d normal = eig.eigenvectors().col(0);  // smallest eigenvalue: across the line
    std::size_t removed = 0;
    for (auto& q : points) {
      if (q.alive && std::abs(normal.dot(Eigen::Vector2d(q.u, q.v) - mean)) <= p.inlier_distance) {
        q.alive = false;
        ++removed;
      }
    }
    ++found;
    if (removed == 0) break;  // cannot happen (the bin's points lie near their own fit), but never loop
  }
  return found;
}

}  // namespace

void HoughLineParams::validate() const {
  require(std::isfinite(angle_step_deg) && angle_step_deg > 0 && angle_step_deg <= 90,
          "angle_step_deg must be in (0, 90], got " + std::to_string(angle_step_deg));
  require(std::isfinite(rho_step) && rho_step > 0, "rho_step must be > 0, got " + std::to_string(rho_step));
  require(std::isfinite(inlier_distance) && inlier_distance > 0,
          "inlier_distance must be > 0, got " + std::to_string(inlier_distance));
  require(min_votes >= 2, "min_votes must be >= 2 (two points make a line)");
  require(max_lines >= 0, "max_lines must be >= 0");
}

HoughRemovalResult remove_lines_hough(const SphereElevationMap& map, const HoughLineParams& params) {
  params.validate();
  const SphereGrid& g = map.grid();
  require(params.rho_step >= g.max_range * 1e-5, "rho_step is too small for the map's range");
  // the vote table of every row at once (one per thread): at most 50 M cells (200 MB) each
  const double table = std::ceil(180.0 / params.angle_step_deg) * (2.0 * std::ceil(g.max_range / params.rho_step) + 1);
  require(table <= 5e7, "the vote table (180 / angle_step_deg x 2 max_range / rho_step) would hold " +
                            std::to_string(static_cast<long long>(std::min(table, 9e18))) +
                            " cells, more than 50,000,000: a coarser angle_step_deg or rho_step");
  HoughRemovalResult result{map, std::vector<std::uint8_t>(g.cells(), 0), 0};
  const int rows = g.rows(), cols = g.cols();
  std::vector<int> lines(static_cast<std::size_t>(rows), 0);
  parallel_for(
      static_cast<std::size_t>(rows), 0,
      [&](std::size_t begin, std::size_t end) {
        std::vector<ScanPoint> points;
        for (std::size_t row = begin; row < end; ++row) {
          points.clear();
          for (int col = 0; col < cols; ++col) {
            const double r = map.range(static_cast<int>(row), col);
            if (std::isnan(r)) continue;
            points.push_back({r * std::cos(g.phi(col)), r * std::sin(g.phi(col)), col, true});
          }
          lines[row] = remove_lines_in_scan(points, params, g.max_range);
          for (const auto& q : points) {
            if (q.alive) continue;
            const std::size_t cell = row * static_cast<std::size_t>(cols) + static_cast<std::size_t>(q.col);
            result.removed[cell] = 1;
            result.kept.ranges()[cell] = std::numeric_limits<double>::quiet_NaN();
          }
        }
      },
      4);
  for (const int n : lines) result.lines += static_cast<std::size_t>(n);
  return result;
}

}  // namespace kiseki
