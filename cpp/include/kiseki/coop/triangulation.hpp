// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <vector>

namespace kiseki {

/// Cooperative positioning (Hirose, Nagata and Kurazume): standing robots at known positions
/// measure the bearing of a moving one, and its position follows by triangulation.
///
/// Each standing robot i at p_i sees the moving robot along the unit ray u_i (bearing phi_i in
/// the world frame, counter-clockwise from +x; in 3-D also the elevation e_i above the horizontal
/// plane). A bearing error d_phi moves the point seen at range r_i by r_i cos(e_i) d_phi across
/// the ray, horizontally (direction t_i); an elevation error d_e by r_i d_e across it, vertically
/// (direction s_i). The estimate is the weighted least-squares point of the rays,
///   x = (sum W_i)^-1 sum W_i p_i,
///   W_i = t_i t_i^T / (r_i cos e_i sigma_phi)^2 [+ s_i s_i^T / (r_i sigma_e)^2 in 3-D],
/// with the ranges r_i taken from a first, unweighted solution (then once more from the
/// weighted one). It is the maximum-likelihood point for small Gaussian angle errors, and for
/// two robots in 2-D the exact intersection of the two lines (the paper's eqs. 1-2). Its
/// covariance to first order is (sum W_i)^-1: for two robots in 2-D exactly the paper's error
/// propagation (eqs. 3-4) for uncorrelated errors of SD sigma, at any geometry.
struct TriangulationParams {
  double bearing_sigma = 0.0;    ///< rad; 0: the covariance is not computed (zero)
  double elevation_sigma = 0.0;  ///< rad; 3-D only; 0: the same as bearing_sigma
  /// Lines of sight meeting at less than this (rad) cannot fix the point: a ValueError. The
  /// angle between two lines, in [0, pi/2]: both near-parallel rays (theta1 + theta2 near 0)
  /// and rays along the baseline (theta1 + theta2 near pi) are caught.
  double min_intersection_angle = 0.017453292519943295;  // 1 deg
};

struct Triangulation {
  Eigen::VectorXd position;    ///< 2 or 3 entries
  Eigen::MatrixXd covariance;  ///< 2x2 or 3x3; zero when bearing_sigma is 0
  Eigen::VectorXd ranges;      ///< from each standing robot
  double intersection_angle = 0.0;  ///< the largest angle between two lines of sight (rad)
};

/// 2-D: standing positions (n >= 2) and their bearings (rad, world frame). Throws
/// std::invalid_argument naming the problem: fewer than two robots, sizes that differ, a
/// non-finite value, coincident robots, lines of sight that are nearly parallel or that do not
/// meet in front of every robot (a bearing pointing away), a moving robot on a standing one.
Triangulation triangulate(const std::vector<Eigen::Vector2d>& standing, const std::vector<double>& bearings,
                          const TriangulationParams& params = {});

/// 3-D with elevation angles (rad, above the horizontal plane, |e| < pi/2).
Triangulation triangulate(const std::vector<Eigen::Vector3d>& standing, const std::vector<double>& bearings,
                          const std::vector<double>& elevations, const TriangulationParams& params = {});

/// Many two-robot triangulations at once (a Monte Carlo sweep): row k intersects the line of
/// sight from a[k] with bearing bearing_a[k] and the one from b[k] with bearing_b[k]. Throws
/// std::invalid_argument naming the row, with the reason triangulate() gives.
std::vector<Eigen::Vector2d> triangulate_pairs(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                                               const std::vector<double>& bearing_a,
                                               const std::vector<double>& bearing_b,
                                               const TriangulationParams& params = {});

}  // namespace kiseki
