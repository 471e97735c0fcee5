// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/coop/triangulation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "kiseki/core/angle.hpp"

namespace kiseki {
namespace {


std::string degrees(double rad) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", rad * 180.0 / kPi);
  return buf;
}

// One line of sight: where it starts, where it points, and the directions across it that the
// angle errors move the point along, each with the error's SD per metre of range.
struct Ray {
  Eigen::Vector3d origin, direction;
  Eigen::Vector3d across_h, across_v;
  double sd_h = 1.0, sd_v = 1.0;  ///< per metre of range, relative: cos(e), sigma_e / sigma_phi
};

void check_params(const TriangulationParams& p) {
  if (!(p.bearing_sigma >= 0.0 && std::isfinite(p.bearing_sigma))) {
    throw std::invalid_argument("triangulate: bearing_sigma must be finite and >= 0");
  }
  if (!(p.elevation_sigma >= 0.0 && std::isfinite(p.elevation_sigma))) {
    throw std::invalid_argument("triangulate: elevation_sigma must be finite and >= 0");
  }
  if (!(p.min_intersection_angle > 0.0 && p.min_intersection_angle <= kPi / 2)) {
    throw std::invalid_argument("triangulate: min_intersection_angle must lie in (0, pi/2]");
  }
}

Triangulation solve(const std::vector<Ray>& rays, int dims, const TriangulationParams& p) {
  const std::size_t n = rays.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double apart = (rays[i].origin - rays[j].origin).norm();
      if (!(apart > 1e-9 * (1.0 + rays[i].origin.norm()))) {
        throw std::invalid_argument("triangulate: standing robots " + std::to_string(i) + " and " +
                                    std::to_string(j) + " coincide");
      }
    }
  }
  // The largest angle between two lines of sight (lines, not rays: in [0, pi/2]).
  double widest = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double c = std::min(1.0, std::abs(rays[i].direction.dot(rays[j].direction)));
      widest = std::max(widest, std::acos(c));
    }
  }
  if (widest < p.min_intersection_angle) {
    throw std::invalid_argument("triangulate: the lines of sight are nearly parallel (they meet at " +
                                degrees(widest) + " deg, below " + degrees(p.min_intersection_angle) +
                                " deg): the bearings cannot fix the position");
  }
  Eigen::VectorXd range = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(n));
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (int pass = 0; pass < 3; ++pass) {  // unweighted, then weighted by the ranges twice
    info.setZero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Ray& r = rays[i];
      const double s = pass == 0 ? 1.0 : range[static_cast<Eigen::Index>(i)];
      Eigen::Matrix3d w = r.across_h * r.across_h.transpose() / std::pow(s * r.sd_h, 2);
      if (dims == 3) w += r.across_v * r.across_v.transpose() / std::pow(s * r.sd_v, 2);
      info += w;
      rhs += w * r.origin;
    }
    if (dims == 2) info(2, 2) = 1.0;  // z is not estimated in 2-D
    x = info.ldlt().solve(rhs);
    if (dims == 2) x.z() = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double along = (x - rays[i].origin).dot(rays[i].direction);
      if (!(along > 0.0)) {
        throw std::invalid_argument("triangulate: the line of sight of standing robot " + std::to_string(i) +
                                    " points away from where the lines meet: a bearing is wrong or "
                                    "the moving robot is behind it");
      }
      const double r = (x - rays[i].origin).norm();
      if (!(r > 1e-9)) {
        throw std::invalid_argument("triangulate: the moving robot is on standing robot " + std::to_string(i));
      }
      range[static_cast<Eigen::Index>(i)] = r;
    }
  }
  Triangulation out;
  out.position = x.head(dims);
  out.ranges = range;
  out.intersection_angle = widest;
  out.covariance = Eigen::MatrixXd::Zero(dims, dims);
  if (p.bearing_sigma > 0.0) {
    // The weights above need only the ratio of the two SDs; the covariance needs the SDs.
    Eigen::Matrix3d info_sigma = Eigen::Matrix3d::Zero();
    const double se = p.elevation_sigma > 0.0 ? p.elevation_sigma : p.bearing_sigma;
    for (std::size_t i = 0; i < n; ++i) {
      const Ray& r = rays[i];
      const double s = range[static_cast<Eigen::Index>(i)];
      info_sigma += r.across_h * r.across_h.transpose() / std::pow(s * r.sd_h * p.bearing_sigma, 2);
      if (dims == 3) info_sigma += r.across_v * r.across_v.transpose() / std::pow(s * se, 2);
    }
    const Eigen::MatrixXd block = info_sigma.topLeftCorner(dims, dims);
    out.covariance = block.inverse();
  }
  return out;
}

}  // namespace

Triangulation triangulate(const std::vector<Eigen::Vector2d>& standing, const std::vector<double>& bearings,
                          const TriangulationParams& params) {
  check_params(params);
  if (standing.size() < 2) throw std::invalid_argument("triangulate: needs at least two standing robots");
  if (bearings.size() != standing.size()) {
    throw std::invalid_argument("triangulate: " + std::to_string(standing.size()) + " standing robots but " +
                                std::to_string(bearings.size()) + " bearings");
  }
  std::vector<Ray> rays(standing.size());
  for (std::size_t i = 0; i < standing.size(); ++i) {
    if (!standing[i].allFinite()) {
      throw std::invalid_argument("triangulate: standing robot " + std::to_string(i) + "'s position is not finite");
    }
    if (!std::isfinite(bearings[i])) {
      throw std::invalid_argument("triangulate: bearing " + std::to_string(i) + " is not finite");
    }
    const double c = std::cos(bearings[i]), s = std::sin(bearings[i]);
    rays[i].origin = Eigen::Vector3d(standing[i].x(), standing[i].y(), 0.0);
    rays[i].direction = Eigen::Vector3d(c, s, 0.0);
    rays[i].across_h = Eigen::Vector3d(-s, c, 0.0);
  }
  return solve(rays, 2, params);
}

Triangulation triangulate(const std::vector<Eigen::Vector3d>& standing, const std::vector<double>& bearings,
                          const std::vector<double>& elevations, const TriangulationParams& params) {
  check_params(params);
  if (standing.size() < 2) throw std::invalid_argument("triangulate: needs at least two standing robots");
  if (bearings.size() != standing.size() || elevations.size() != standing.size()) {
    throw std::invalid_argument("triangulate: " + std::to_string(standing.size()) + " standing robots but " +
                                std::to_string(bearings.size()) + " bearings and " +
                                std::to_string(elevations.size()) + " elevations");
  }
  const double ratio = params.elevation_sigma > 0.0 && params.bearing_sigma > 0.0
                           ? params.elevation_sigma / params.bearing_sigma
                           : 1.0;
  std::vector<Ray> rays(standing.size());
  for (std::size_t i = 0; i < standing.size(); ++i) {
    if (!standing[i].allFinite()) {
      throw std::invalid_argument("triangulate: standing robot " + std::to_string(i) + "'s position is not finite");
    }
    if (!std::isfinite(bearings[i]) || !std::isfinite(elevations[i])) {
      throw std::invalid_argument("triangulate: bearing or elevation " + std::to_string(i) + " is not finite");
    }
    if (!(std::abs(elevations[i]) < kPi / 2 - 1e-6)) {
      throw std::invalid_argument("triangulate: elevation " + std::to_string(i) +
                                  " must lie strictly between -pi/2 and pi/2 (straight up or down has no bearing)");
    }
    const double c = std::cos(bearings[i]), s = std::sin(bearings[i]);
    const double ce = std::cos(elevations[i]), se = std::sin(elevations[i]);
    rays[i].origin = standing[i];
    rays[i].direction = Eigen::Vector3d(ce * c, ce * s, se);
    rays[i].across_h = Eigen::Vector3d(-s, c, 0.0);
    rays[i].across_v = Eigen::Vector3d(-se * c, -se * s, ce);
    rays[i].sd_h = ce;      // a bearing error moves the point by r cos(e) d_phi
    rays[i].sd_v = ratio;   // an elevation error by r d_e (relative weight sigma_e / sigma_phi)
  }
  return solve(rays, 3, params);
}

std::vector<Eigen::Vector2d> triangulate_pairs(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                                               const std::vector<double>& bearing_a,
                                               const std::vector<double>& bearing_b,
                                               const TriangulationParams& params) {
  const std::size_t m = a.size();
  if (b.size() != m || bearing_a.size() != m || bearing_b.size() != m) {
    throw std::invalid_argument("triangulate_pairs: the four inputs need the same number of rows");
  }
  TriangulationParams p = params;
  p.bearing_sigma = 0.0;  // positions only
  std::vector<Eigen::Vector2d> out(m);
  for (std::size_t k = 0; k < m; ++k) {
    try {
      const Triangulation t = triangulate({a[k], b[k]}, {bearing_a[k], bearing_b[k]}, p);
      out[k] = t.position.head<2>();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("row " + std::to_string(k) + ": " + e.what());
    }
  }
  return out;
}

}  // namespace kiseki
