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
constexpr Eigen::Index kMaxBlock = 1024;     // prediction points per block
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
                                           const SquaredExponential& kernel, GpMean mean,
                                           bool truncated_prediction)
    : kernel_(kernel), truncated_(truncated_prediction) {
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
  factor_ = gp_detail::cholesky_with_jitter(cov, &jitter_, "Gaussian process");
  cov.resize(0, 0);
  const Eigen::MatrixXd& l = factor_;
  alpha_ = y;
  gp_detail::cholesky_solve(l, alpha_);
  // Blocks of prediction points far apart use parts of the inverse (see predict()).
  if (truncated_ && n > kDenseBelow) inverse_ = gp_detail::inverse_from_cholesky(l);
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
  const bool dense = !truncated_ || truncation == 0.0 || n <= kDenseBelow;
  // Block boundaries: every kMaxBlock points; without `dense`, also wherever the tile changes.
  std::vector<Eigen::Index> starts;
  if (dense) {
    for (Eigen::Index b = 0; b < m; b += kMaxBlock) starts.push_back(b);
  } else {
    const double tile = 2.0 * kernel_.length_scale;
    std::vector<std::vector<long long>> keys(static_cast<std::size_t>(m));
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index c = 0; c < p.cols(); ++c) keys[i].push_back(static_cast<long long>(std::floor(p(i, c) / tile)));
    }
    std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return keys[a] < keys[b]; });
    for (Eigen::Index i = 0; i < m; ++i) {
      if (i == 0 || keys[order[i]] != keys[order[i - 1]] || i - starts.back() >= kMaxBlock) starts.push_back(i);
    }
  }
  starts.push_back(m);
  const double radius = dense ? 0.0 : kernel_.cutoff_radius(truncation);
  const auto blocks = static_cast<Eigen::Index>(starts.size()) - 1;

  // The blocks on OpenMP's threads, each block's products on the thread that takes it: every
  // block writes its own rows, by the same calls whichever thread takes it.
#pragma omp parallel for schedule(dynamic, 1) if (blocks > 1)
  for (Eigen::Index b = 0; b < blocks; ++b) {
    const Eigen::Index begin = starts[static_cast<std::size_t>(b)];
    const Eigen::Index count = starts[static_cast<std::size_t>(b + 1)] - begin;
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
    auto s = static_cast<Eigen::Index>(near.size());
    // Beyond half the training points a block is cheaper with the triangular factor: n^2 per
    // point against 2 s^2 with the inverse's sub-block.
    const bool use_factor = dense || 2 * s > n;
    if (use_factor && s != n) {
      near.resize(static_cast<std::size_t>(n));
      std::iota(near.begin(), near.end(), Eigen::Index{0});
      s = n;
    }
    const Eigen::MatrixXd ks = use_factor ? kernel_matrix(kernel_, q, inputs_) : [&] {
      RowMatrix xs(s, p.cols());
      for (Eigen::Index j = 0; j < s; ++j) xs.row(j) = inputs_.row(near[static_cast<std::size_t>(j)]);
      return kernel_matrix(kernel_, q, xs);
    }();  // count x s
    Eigen::MatrixXd alpha_s(s, outputs());
    for (Eigen::Index j = 0; j < s; ++j) alpha_s.row(j) = alpha_.row(near[static_cast<std::size_t>(j)]);
    const Eigen::MatrixXd mu = gp_detail::multiply(ks, alpha_s);  // eq. 6.8
    Eigen::VectorXd var;
    if (variance != nullptr) {
      // Eq. 6.9: k** - k*^T (K + sn^2 I)^-1 k*.
      if (use_factor) {
        Eigen::MatrixXd v = ks.transpose();
        gp_detail::lower_solve(factor_, v);  // L^-1 k*
        var = (f2 - v.colwise().squaredNorm().array()).cwiseMax(0.0).matrix().transpose();
      } else {
        Eigen::MatrixXd inv_s(s, s);
        for (Eigen::Index c = 0; c < s; ++c) {
          for (Eigen::Index r = 0; r < s; ++r) inv_s(r, c) = inverse_(near[r], near[c]);
        }
        const Eigen::MatrixXd projected = gp_detail::multiply(ks, inv_s);
        var = (f2 - (projected.array() * ks.array()).rowwise().sum()).cwiseMax(0.0).matrix();
      }
    }
    for (Eigen::Index r = 0; r < count; ++r) {
      const Eigen::Index row = order[static_cast<std::size_t>(begin + r)];
      mean.row(row) = mu.row(r) + prior_mean_.transpose();
      if (variance != nullptr) (*variance)(row) = var(r);
    }
  }
}

}  // namespace kiseki
