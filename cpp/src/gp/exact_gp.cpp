// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/gp/exact_gp.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "dense.hpp"

namespace kiseki {

namespace {
constexpr double kLog2Pi = 1.8378770664093454836;
constexpr Eigen::Index kDenseBelow = 2000;  // training points up to which predict uses them all
constexpr Eigen::Index kMaxBlock = 512;      // prediction points per block
}  // namespace

void check_training_data(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets) {
  const Eigen::Index n = inputs.rows();
  const Eigen::Index d = inputs.cols();
  if (d < 1) throw std::invalid_argument("Gaussian process: the inputs have no coordinates");
  if (targets.rows() != n) {
    throw std::invalid_argument("Gaussian process: " + std::to_string(n) + " input points but " +
                                std::to_string(targets.rows()) + " target rows");
  }
  if (targets.cols() < 1) throw std::invalid_argument("Gaussian process: the targets have no columns");
  if (n <= d) {
    throw std::invalid_argument("Gaussian process: " + std::to_string(n) + " points in " + std::to_string(d) +
                                " dimensions; at least " + std::to_string(d + 1) + " are needed");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!inputs.row(i).allFinite()) {
      throw std::invalid_argument("Gaussian process: input point " + std::to_string(i) + " is NaN or infinite");
    }
    if (!targets.row(i).allFinite()) {
      throw std::invalid_argument("Gaussian process: target row " + std::to_string(i) + " is NaN or infinite");
    }
  }
  const Eigen::RowVectorXd span = inputs.colwise().maxCoeff() - inputs.colwise().minCoeff();
  if (span.maxCoeff() <= 0.0) {
    throw std::invalid_argument("Gaussian process: all " + std::to_string(n) +
                                " input points are identical; the field cannot be learnt from one place");
  }
}

ExactGaussianProcess::ExactGaussianProcess(const Eigen::Ref<const RowMatrix>& inputs,
                                           const Eigen::Ref<const RowMatrix>& targets,
                                           const SquaredExponential& kernel, GpMean mean)
    : kernel_(kernel) {
  kernel_.validate();
  check_training_data(inputs, targets);
  const Eigen::Index n = inputs.rows();
  const Eigen::Index k = targets.cols();
  centre_ = inputs.colwise().mean();
  inputs_ = inputs.rowwise() - centre_;
  prior_mean_ = mean == GpMean::constant ? Eigen::VectorXd(targets.colwise().mean().transpose())
                                         : Eigen::VectorXd::Zero(k);
  Eigen::MatrixXd y = targets;
  y.rowwise() -= prior_mean_.transpose();

  Eigen::MatrixXd cov = kernel_matrix(kernel_, inputs_, inputs_);
  cov.diagonal().array() += kernel_.sigma_n * kernel_.sigma_n;
  const Eigen::MatrixXd l = gp_detail::cholesky_with_jitter(cov, &jitter_, "Gaussian process");
  alpha_ = y;
  gp_detail::cholesky_solve(l, alpha_);
  inverse_ = gp_detail::inverse_from_cholesky(l);
  // Eq. 6.11 per column, summed: -1/2 y^T alpha - 1/2 log|K + sn^2 I| - n/2 log 2 pi.
  log_marginal_likelihood_ = -0.5 * (y.array() * alpha_.array()).sum() -
                             0.5 * static_cast<double>(k) * gp_detail::log_determinant(l) -
                             0.5 * static_cast<double>(k * n) * kLog2Pi;
}

void ExactGaussianProcess::predict(const Eigen::Ref<const RowMatrix>& points, RowMatrix& mean,
                                   Eigen::VectorXd* variance, double truncation) const {
  if (points.cols() != dimension()) {
    throw std::invalid_argument("Gaussian process: prediction points have " + std::to_string(points.cols()) +
                                " coordinates, the training inputs " + std::to_string(dimension()));
  }
  if (!(truncation >= 0.0 && truncation < 1.0)) throw std::invalid_argument("predict: truncation must be in [0, 1)");
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) {
      throw std::invalid_argument("Gaussian process: prediction point " + std::to_string(i) + " is NaN or infinite");
    }
  }
  const Eigen::Index m = points.rows();
  const Eigen::Index n = size();
  const double f2 = kernel_.sigma_f * kernel_.sigma_f;
  mean.resize(m, outputs());
  if (variance != nullptr) variance->resize(m);
  if (m == 0) return;
  const RowMatrix p = points.rowwise() - centre_;

  // Blocks of nearby points: sorted by a tile key of two length scales, so that each block needs
  // only the training points within the cutoff radius of its bounding box.
  std::vector<Eigen::Index> order(static_cast<std::size_t>(m));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  const bool dense = truncation == 0.0 || n <= kDenseBelow;
  if (!dense) {
    const double tile = 2.0 * kernel_.length_scale;
    std::vector<std::vector<long long>> keys(static_cast<std::size_t>(m));
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index c = 0; c < p.cols(); ++c) keys[i].push_back(static_cast<long long>(std::floor(p(i, c) / tile)));
    }
    std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return keys[a] < keys[b]; });
  }
  const double radius = dense ? 0.0 : kernel_.cutoff_radius(truncation);
  const Eigen::Index blocks = (m + kMaxBlock - 1) / kMaxBlock;

  // Blocks one after another: the products inside run on every core through BLAS.
  for (Eigen::Index b = 0; b < blocks; ++b) {
    const Eigen::Index begin = b * kMaxBlock;
    const Eigen::Index count = std::min(kMaxBlock, m - begin);
    RowMatrix q(count, p.cols());
    for (Eigen::Index r = 0; r < count; ++r) q.row(r) = p.row(order[static_cast<std::size_t>(begin + r)]);
    std::vector<Eigen::Index> near;
    if (dense) {
      near.resize(static_cast<std::size_t>(n));
      std::iota(near.begin(), near.end(), Eigen::Index{0});
    } else {
      const Eigen::RowVectorXd lo = q.colwise().minCoeff();
      const Eigen::RowVectorXd hi = q.colwise().maxCoeff();
      for (Eigen::Index j = 0; j < n; ++j) {
        const Eigen::RowVectorXd x = inputs_.row(j);
        const Eigen::RowVectorXd gap = (lo - x).cwiseMax(x - hi).cwiseMax(0.0);
        if (gap.norm() <= radius) near.push_back(j);
      }
    }
    const auto s = static_cast<Eigen::Index>(near.size());
    RowMatrix xs(s, p.cols());
    Eigen::MatrixXd alpha_s(s, outputs());
    for (Eigen::Index j = 0; j < s; ++j) {
      xs.row(j) = inputs_.row(near[static_cast<std::size_t>(j)]);
      alpha_s.row(j) = alpha_.row(near[static_cast<std::size_t>(j)]);
    }
    const Eigen::MatrixXd ks = kernel_matrix(kernel_, q, xs);  // count x s
    const Eigen::MatrixXd mu = gp_detail::multiply(ks, alpha_s);
    Eigen::VectorXd var;
    if (variance != nullptr) {
      Eigen::MatrixXd projected;
      if (s == n) {
        projected = gp_detail::multiply(ks, inverse_);
      } else {
        Eigen::MatrixXd inv_s(s, s);
        for (Eigen::Index c = 0; c < s; ++c) {
          for (Eigen::Index r = 0; r < s; ++r) inv_s(r, c) = inverse_(near[r], near[c]);
        }
        projected = gp_detail::multiply(ks, inv_s);
      }
      // Eq. 6.9: k** - k*^T (K + sn^2 I)^-1 k*.
      var = (f2 - (projected.array() * ks.array()).rowwise().sum()).cwiseMax(0.0).matrix();
    }
    for (Eigen::Index r = 0; r < count; ++r) {
      const Eigen::Index row = order[static_cast<std::size_t>(begin + r)];
      mean.row(row) = mu.row(r) + prior_mean_.transpose();
      if (variance != nullptr) (*variance)(row) = var(r);
    }
  }
}

}  // namespace kiseki
