// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/gp/hilbert_gp.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "dense.hpp"
#include "kiseki/core/angle.hpp"

namespace kiseki {

namespace {
constexpr Eigen::Index kChunk = 4096;  // rows of Phi built at once
}  // namespace

HilbertGaussianProcess::HilbertGaussianProcess(const Eigen::Ref<const RowMatrix>& inputs,
                                               const Eigen::Ref<const RowMatrix>& targets,
                                               const SquaredExponential& kernel, const Eigen::VectorXd& lower,
                                               const Eigen::VectorXd& upper, double tolerance, Eigen::Index max_basis,
                                               GpMean mean)
    : kernel_(kernel), lower_(lower), upper_(upper), size_(inputs.rows()) {
  kernel_.validate();
  check_training_data(inputs, targets);
  const Eigen::Index d = inputs.cols();
  if (d > 3) throw std::invalid_argument("Hilbert-space GP: at most 3 input dimensions, got " + std::to_string(d));
  if (lower.size() != d || upper.size() != d) {
    throw std::invalid_argument("Hilbert-space GP: the domain's corners must have " + std::to_string(d) + " coordinates");
  }
  if (!lower.allFinite() || !upper.allFinite() || (upper - lower).minCoeff() <= 0.0) {
    throw std::invalid_argument("Hilbert-space GP: the domain must be a finite box with upper > lower");
  }
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw std::invalid_argument("Hilbert-space GP: tolerance must be in (0, 1)");
  if (max_basis < 1) throw std::invalid_argument("Hilbert-space GP: max_basis must be >= 1");
  for (Eigen::Index i = 0; i < inputs.rows(); ++i) {
    const Eigen::VectorXd x = inputs.row(i).transpose();
    if ((x - lower).minCoeff() <= 0.0 || (upper - x).minCoeff() <= 0.0) {
      throw std::invalid_argument("Hilbert-space GP: training point " + std::to_string(i) +
                                  " lies outside the domain (enlarge it by a few length scales)");
    }
  }
  // The frequencies to keep: w_max from S(w_max) = tolerance S(0).
  const double w_max = std::sqrt(-2.0 * std::log(tolerance)) / kernel_.length_scale;
  const Eigen::VectorXd half = 0.5 * (upper - lower);
  std::vector<int> top(static_cast<std::size_t>(d));
  double count = 1.0;
  for (Eigen::Index c = 0; c < d; ++c) {
    top[c] = static_cast<int>(std::floor(w_max * 2.0 * half(c) / kPi));
    if (top[c] < 1) top[c] = 1;
    count *= top[c];
  }
  std::vector<Eigen::Vector3i> kept;
  std::vector<int> j(3, 1);
  for (j[0] = 1; j[0] <= top[0]; ++j[0]) {
    for (j[1] = 1; j[1] <= (d > 1 ? top[1] : 1); ++j[1]) {
      for (j[2] = 1; j[2] <= (d > 2 ? top[2] : 1); ++j[2]) {
        double lambda = 0.0;
        for (Eigen::Index c = 0; c < d; ++c) lambda += std::pow(kPi * j[c] / (2.0 * half(c)), 2);
        if (std::sqrt(lambda) <= w_max || kept.empty()) kept.emplace_back(j[0], j[1], j[2]);
        if (static_cast<Eigen::Index>(kept.size()) > max_basis) {
          throw std::invalid_argument("Hilbert-space GP: the kernel's length scale " +
                                      std::to_string(kernel_.length_scale) + " on this domain needs more than " +
                                      std::to_string(max_basis) +
                                      " basis functions (raise max_basis or the tolerance, or use a smaller domain)");
        }
      }
    }
  }
  (void)count;
  const auto m = static_cast<Eigen::Index>(kept.size());
  frequencies_.resize(m, d);
  Eigen::VectorXd spectral(m);
  const double f2 = kernel_.sigma_f * kernel_.sigma_f;
  const double l2 = kernel_.length_scale * kernel_.length_scale;
  for (Eigen::Index b = 0; b < m; ++b) {
    double lambda = 0.0;
    for (Eigen::Index c = 0; c < d; ++c) {
      frequencies_(b, c) = kept[static_cast<std::size_t>(b)](c);
      lambda += std::pow(kPi * frequencies_(b, c) / (2.0 * half(c)), 2);
    }
    spectral(b) = f2 * std::pow(2.0 * kPi * l2, 0.5 * static_cast<double>(d)) * std::exp(-0.5 * lambda * l2);
  }

  prior_mean_ = mean == GpMean::constant ? Eigen::VectorXd(targets.colwise().mean().transpose())
                                         : Eigen::VectorXd::Zero(targets.cols());
  Eigen::MatrixXd z = Eigen::MatrixXd::Zero(m, m);
  beta_ = Eigen::MatrixXd::Zero(m, targets.cols());
  for (Eigen::Index begin = 0; begin < size_; begin += kChunk) {
    const Eigen::Index rows = std::min(kChunk, size_ - begin);
    const Eigen::MatrixXd phi = basis(inputs.middleRows(begin, rows));
    z += gp_detail::gram(phi);
    Eigen::MatrixXd y = targets.middleRows(begin, rows);
    y.rowwise() -= prior_mean_.transpose();
    beta_ += phi.transpose() * y;
  }
  z.diagonal().array() += kernel_.sigma_n * kernel_.sigma_n / spectral.array();
  double jitter = 0.0;
  factor_ = gp_detail::cholesky_with_jitter(z, &jitter, "Hilbert-space GP");
  gp_detail::cholesky_solve(factor_, beta_);
}

Eigen::MatrixXd HilbertGaussianProcess::basis(const Eigen::Ref<const RowMatrix>& x) const {
  const Eigen::Index d = dimension();
  const Eigen::Index m = basis_size();
  const Eigen::VectorXd half = 0.5 * (upper_ - lower_);
  const int top = frequencies_.maxCoeff();
  Eigen::MatrixXd phi(x.rows(), m);
#pragma omp parallel for schedule(static) if (x.rows() > 256)
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    // sin(pi j (x - lower) / (2 L)) / sqrt(L) for j = 1..top, per dimension.
    Eigen::MatrixXd s(top + 1, d);
    for (Eigen::Index c = 0; c < d; ++c) {
      const double u = kPi * (x(i, c) - lower_(c)) / (2.0 * half(c));
      for (int jj = 1; jj <= top; ++jj) s(jj, c) = std::sin(jj * u) / std::sqrt(half(c));
    }
    for (Eigen::Index b = 0; b < m; ++b) {
      double v = 1.0;
      for (Eigen::Index c = 0; c < d; ++c) v *= s(frequencies_(b, c), c);
      phi(i, b) = v;
    }
  }
  return phi;
}

void HilbertGaussianProcess::predict(const Eigen::Ref<const RowMatrix>& points, RowMatrix& mean,
                                     Eigen::VectorXd* variance) const {
  if (points.cols() != dimension()) {
    throw std::invalid_argument("Hilbert-space GP: prediction points have " + std::to_string(points.cols()) +
                                " coordinates, the training inputs " + std::to_string(dimension()));
  }
  const Eigen::Index n = points.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!points.row(i).allFinite()) {
      throw std::invalid_argument("Hilbert-space GP: prediction point " + std::to_string(i) + " is NaN or infinite");
    }
  }
  mean.resize(n, outputs());
  if (variance != nullptr) variance->resize(n);
  const double f2 = kernel_.sigma_f * kernel_.sigma_f;
  const double sn2 = kernel_.sigma_n * kernel_.sigma_n;
  for (Eigen::Index begin = 0; begin < n; begin += kChunk) {
    const Eigen::Index rows = std::min(kChunk, n - begin);
    // Points outside the domain get the prior; the rest the basis expansion.
    std::vector<Eigen::Index> inside;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const Eigen::VectorXd x = points.row(begin + r).transpose();
      if ((x - lower_).minCoeff() > 0.0 && (upper_ - x).minCoeff() > 0.0) {
        inside.push_back(begin + r);
      } else {
        mean.row(begin + r) = prior_mean_.transpose();
        if (variance != nullptr) (*variance)(begin + r) = f2;
      }
    }
    if (inside.empty()) continue;
    RowMatrix x(static_cast<Eigen::Index>(inside.size()), dimension());
    for (std::size_t r = 0; r < inside.size(); ++r) x.row(static_cast<Eigen::Index>(r)) = points.row(inside[r]);
    const Eigen::MatrixXd phi = basis(x);
    const Eigen::MatrixXd mu = gp_detail::multiply(phi, beta_);
    Eigen::VectorXd var;
    if (variance != nullptr) {
      Eigen::MatrixXd v = phi.transpose();
      gp_detail::lower_solve(factor_, v);
      var = sn2 * v.colwise().squaredNorm().transpose();
    }
    for (std::size_t r = 0; r < inside.size(); ++r) {
      const auto row = static_cast<Eigen::Index>(r);
      mean.row(inside[r]) = mu.row(row) + prior_mean_.transpose();
      if (variance != nullptr) (*variance)(inside[r]) = std::min(var(row), f2);
    }
  }
}

}  // namespace kiseki
