// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>

namespace kiseki {

/// Row-major matrices: one input point (x, y[, z]) or one target vector (mx, my, mz) per row,
/// the layout numpy hands over without a copy.
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The squared-exponential covariance of the magnetic-navigation thesis (chapter 6, eq. 6.2):
/// k(p, q) = sigma_f^2 exp(-|p - q|^2 / (2 l^2)), with independent measurement noise sigma_n^2
/// added on the diagonal of the training covariance (eqs. 6.3-6.4).
struct SquaredExponential {
  double sigma_f = 1.0;       ///< signal standard deviation (the targets' units)
  double length_scale = 1.0;  ///< l (the inputs' units, metres)
  double sigma_n = 0.1;       ///< measurement noise standard deviation (the targets' units)

  /// Throws std::invalid_argument unless all three are finite and > 0.
  void validate() const;
  /// k(p, q) from the squared distance |p - q|^2.
  double operator()(double squared_distance) const;
  /// The distance beyond which k < relative * sigma_f^2 (the truncation radius of a prediction).
  double cutoff_radius(double relative) const;
};

/// |a_i - b_j|^2 for every row pair, computed coordinate by coordinate (not by the
/// |a|^2 + |b|^2 - 2 a.b expansion, whose cancellation loses digits far from the origin).
Eigen::MatrixXd squared_distances(const Eigen::Ref<const RowMatrix>& a, const Eigen::Ref<const RowMatrix>& b);

/// The noise-free kernel matrix K(a, b).
Eigen::MatrixXd kernel_matrix(const SquaredExponential& kernel, const Eigen::Ref<const RowMatrix>& a,
                              const Eigen::Ref<const RowMatrix>& b);

}  // namespace kiseki
