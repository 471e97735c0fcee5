// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>

#include "kiseki/gp/squared_exponential.hpp"

namespace kiseki {

/// The mean function under the GP: none, or the training mean of each target column (removed
/// before the fit and added back to predictions).
enum class GpMean { zero, constant };

/// Checks training data: rows of inputs (n x d) and targets (n x k), n equal, finite, more points
/// than dimensions, not all inputs identical. Throws std::invalid_argument naming the problem.
void check_training_data(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets);

/// Exact Gaussian-process regression (thesis chapter 6, eqs. 6.7-6.9): every target column is an
/// independent GP with the same kernel and the same inputs, so one Cholesky factorisation of
/// K + sigma_n^2 I serves all of them (the thesis fits mx, my and mz one by one; with shared
/// hyperparameters that is the same model at a third of the cost).
///
/// The inputs are centred on their mean before anything is computed, so coordinates far from the
/// origin (UTM, a building's survey frame) lose no digits.
class ExactGaussianProcess {
 public:
  /// truncated_prediction false: predict always uses every training point through the factor,
  /// and the inverse that truncated prediction needs (2 n^3 / 3 more operations, twice the
  /// factorisation's) is not computed: for a GP whose predictions all lie near its data (a tile
  /// of kiseki.gp.TiledGP).
  ExactGaussianProcess(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets,
                       const SquaredExponential& kernel, GpMean mean = GpMean::constant,
                       bool truncated_prediction = true);

  /// Predictive mean (eq. 6.8) of every column at m points (m x k), and, when variance is not
  /// null, the variance of the noise-free field (eq. 6.9; the same for every column), one per
  /// point. Kernel values below truncation * sigma_f^2 are dropped: each block of nearby points
  /// uses only the training points within the kernel's cutoff radius, with the matching block of
  /// (K + sigma_n^2 I)^-1 (truncation 0, or a GP built without truncated prediction = use every
  /// training point).
  void predict(const Eigen::Ref<const RowMatrix>& points, RowMatrix& mean, Eigen::VectorXd* variance,
               double truncation = 1e-13) const;

  /// log p(Y | X, theta), eq. 6.11, summed over the target columns.
  double log_marginal_likelihood() const { return log_marginal_likelihood_; }
  const SquaredExponential& kernel() const { return kernel_; }
  Eigen::Index size() const { return inputs_.rows(); }
  Eigen::Index dimension() const { return inputs_.cols(); }
  Eigen::Index outputs() const { return alpha_.cols(); }
  /// The mean function's value per column (zeros for GpMean::zero).
  const Eigen::VectorXd& prior_mean() const { return prior_mean_; }
  /// The jitter added to the diagonal to factorise K + sigma_n^2 I (0 almost always).
  double jitter() const { return jitter_; }

 private:
  SquaredExponential kernel_;
  Eigen::RowVectorXd centre_;
  RowMatrix inputs_;            // centred
  Eigen::VectorXd prior_mean_;  // k
  Eigen::MatrixXd alpha_;       // (K + sn^2 I)^-1 (Y - mean), n x k
  Eigen::MatrixXd factor_;      // the lower Cholesky factor of K + sn^2 I
  Eigen::MatrixXd inverse_;     // (K + sn^2 I)^-1 (only above the dense limit), n x n
  double log_marginal_likelihood_ = 0.0;
  double jitter_ = 0.0;
  bool truncated_ = true;
};

}  // namespace kiseki
