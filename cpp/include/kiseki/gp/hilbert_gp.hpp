// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <vector>

#include "kiseki/gp/exact_gp.hpp"

namespace kiseki {

/// Reduced-rank ("Hilbert-space") Gaussian-process regression: Solin & Sarkka, "Hilbert space
/// methods for reduced-rank Gaussian process regression", Statistics and Computing 30, 2020.
///
/// On a box domain Omega = [lower, upper] with Dirichlet boundaries the kernel is approximated by
/// the Laplacian's eigenfunctions phi_j(x) = prod_d L_d^-1/2 sin(pi j_d (x_d - lower_d) / (2 L_d))
/// (L_d the half-width of the box) weighted by the squared-exponential's spectral density
/// S(w) = sigma_f^2 (2 pi l^2)^(d/2) exp(-w^2 l^2 / 2) at w = sqrt(lambda_j),
/// lambda_j = sum_d (pi j_d / (2 L_d))^2. With Phi (n x m) the basis at the training inputs and
/// Lambda = diag(S(sqrt(lambda_j))):
///   Z = Phi^T Phi + sigma_n^2 Lambda^-1,  mean* = phi*^T Z^-1 Phi^T y,
///   variance* = sigma_n^2 phi*^T Z^-1 phi*   (the paper's eqs. 19-20).
/// Cost O(n m^2) to fit, O(m^2) per predicted variance, independent of n.
///
/// The basis keeps every j with sqrt(lambda_j) <= w_max, where S(w_max) = tolerance S(0): the
/// frequencies the kernel actually has (an ellipsoidal truncation). The domain must hold the
/// data with a margin of a few length scales: near the boundary the approximation goes to the
/// prior mean.
class HilbertGaussianProcess {
 public:
  HilbertGaussianProcess(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets,
                         const SquaredExponential& kernel, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                         double tolerance = 1e-4, Eigen::Index max_basis = 20000, GpMean mean = GpMean::constant);

  /// As ExactGaussianProcess::predict (variance of the noise-free field); points outside the
  /// domain get the prior (mean, sigma_f^2).
  void predict(const Eigen::Ref<const RowMatrix>& points, RowMatrix& mean, Eigen::VectorXd* variance) const;

  /// The number of basis functions m.
  Eigen::Index basis_size() const { return frequencies_.rows(); }
  const SquaredExponential& kernel() const { return kernel_; }
  Eigen::Index size() const { return size_; }
  Eigen::Index dimension() const { return lower_.size(); }
  Eigen::Index outputs() const { return beta_.cols(); }
  const Eigen::VectorXd& prior_mean() const { return prior_mean_; }
  const Eigen::VectorXd& lower() const { return lower_; }
  const Eigen::VectorXd& upper() const { return upper_; }

 private:
  /// Phi at rows of x (all inside the domain): rows x m, column-major.
  Eigen::MatrixXd basis(const Eigen::Ref<const RowMatrix>& x) const;

  SquaredExponential kernel_;
  Eigen::VectorXd lower_, upper_;
  Eigen::Index size_ = 0;
  Eigen::MatrixXi frequencies_;  // m x d, the j_d of each basis function
  Eigen::VectorXd prior_mean_;
  Eigen::MatrixXd factor_;  // the Cholesky factor of Z
  Eigen::MatrixXd beta_;    // Z^-1 Phi^T y, m x k
};

}  // namespace kiseki
