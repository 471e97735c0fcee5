// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/gp/hyperparameters.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "dense.hpp"
#include "kiseki/core/random.hpp"

namespace kiseki {

namespace {

constexpr double kLog2Pi = 1.8378770664093454836;

SquaredExponential from_log(const Eigen::Vector3d& x) { return {std::exp(x(0)), std::exp(x(1)), std::exp(x(2))}; }
Eigen::Vector3d to_log(const SquaredExponential& k) {
  return {std::log(k.sigma_f), std::log(k.length_scale), std::log(k.sigma_n)};
}

double rms(const Eigen::Ref<const RowMatrix>& targets) {
  const double r = std::sqrt(targets.array().square().mean());
  return r > 0.0 ? r : 1.0;
}

double extent(const Eigen::Ref<const RowMatrix>& inputs) {
  return (inputs.colwise().maxCoeff() - inputs.colwise().minCoeff()).maxCoeff();
}

}  // namespace

namespace {

/// Eq. 6.11 and its gradient from the inputs' squared distances (computed once per fit).
LogMarginalLikelihood from_distances(const Eigen::MatrixXd& d2, const Eigen::Ref<const RowMatrix>& targets,
                                     const SquaredExponential& kernel) {
  kernel.validate();
  const Eigen::Index n = d2.rows();
  const Eigen::Index k = targets.cols();
  const double l2 = kernel.length_scale * kernel.length_scale;
  const double sn2 = kernel.sigma_n * kernel.sigma_n;
  // As kernel_matrix: no subnormal values (see there).
  const Eigen::ArrayXXd exponent = d2.array() * (-0.5 / l2);
  Eigen::MatrixXd kf = (exponent < -700.0).select(0.0, exponent.exp() * (kernel.sigma_f * kernel.sigma_f)).matrix();
  Eigen::MatrixXd l = kf;
  l.diagonal().array() += sn2;
  if (!gp_detail::cholesky(l)) {
    throw std::runtime_error("log marginal likelihood: K + sigma_n^2 I is not positive definite");
  }
  Eigen::MatrixXd alpha = targets;
  gp_detail::cholesky_solve(l, alpha);
  const Eigen::MatrixXd inv = gp_detail::inverse_from_cholesky(l);
  LogMarginalLikelihood out;
  out.value = -0.5 * (targets.array() * alpha.array()).sum() -
              0.5 * static_cast<double>(k) * gp_detail::log_determinant(l) -
              0.5 * static_cast<double>(n * k) * kLog2Pi;
  // W = alpha alpha^T - k K^-1; dK/dlog sf = 2 Kf (eq. 6.13 x sf), dK/dlog l = Kf D^2 / l^2
  // (eq. 6.14 x l), dK/dlog sn = 2 sn^2 I (eq. 6.15 x sn); each term is 1/2 sum(W o dK).
  // Per-column partial sums, added in a fixed order afterwards: the same result for any
  // number of threads.
  Eigen::MatrixX3d partial(n, 3);
#pragma omp parallel for schedule(static) if (n > 500)
  for (Eigen::Index j = 0; j < n; ++j) {
    double f = 0.0;
    double ls = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double w = alpha.row(i).dot(alpha.row(j)) - static_cast<double>(k) * inv(i, j);
      f += w * kf(i, j);
      ls += w * kf(i, j) * d2(i, j);
    }
    partial(j, 0) = f;
    partial(j, 1) = ls;
    partial(j, 2) = alpha.row(j).squaredNorm() - static_cast<double>(k) * inv(j, j);
  }
  const double g_f = partial.col(0).sum();
  const double g_l = partial.col(1).sum();
  const double trace_w = partial.col(2).sum();
  out.gradient = {g_f, 0.5 * g_l / l2, sn2 * trace_w};
  return out;
}

}  // namespace

LogMarginalLikelihood log_marginal_likelihood(const Eigen::Ref<const RowMatrix>& inputs,
                                              const Eigen::Ref<const RowMatrix>& targets,
                                              const SquaredExponential& kernel) {
  if (inputs.rows() != targets.rows()) throw std::invalid_argument("log_marginal_likelihood: row counts differ");
  return from_distances(squared_distances(inputs, inputs), targets, kernel);
}

SquaredExponential initial_kernel(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets) {
  check_training_data(inputs, targets);
  const double s = rms(targets);
  return {s, 0.1 * extent(inputs), 0.1 * s};
}

HyperparameterFit fit_hyperparameters(const Eigen::Ref<const RowMatrix>& inputs,
                                      const Eigen::Ref<const RowMatrix>& targets,
                                      const SquaredExponential& initial, const HyperparameterOptions& options) {
  check_training_data(inputs, targets);
  initial.validate();
  if (options.restarts < 0 || options.max_iterations < 1 || !(options.tolerance > 0.0)) {
    throw std::invalid_argument("fit_hyperparameters: restarts >= 0, max_iterations >= 1 and tolerance > 0 needed");
  }
  const RowMatrix x = inputs.rowwise() - inputs.colwise().mean();
  const double s = rms(targets);
  const double e = extent(x);
  const Eigen::Vector3d lower(std::log(1e-6 * s), std::log(1e-3 * e), std::log(1e-6 * s));
  const Eigen::Vector3d upper(std::log(1e3 * s), std::log(1e2 * e), std::log(1e3 * s));
  const double scale = 1.0 / static_cast<double>(x.rows() * targets.cols());
  const Eigen::MatrixXd d2 = squared_distances(x, x);

  HyperparameterFit fit;
  fit.log_marginal_likelihood = -std::numeric_limits<double>::infinity();
  // f = -LML / (n k), minimised; +inf where K cannot be factorised.
  const auto evaluate = [&](const Eigen::Vector3d& p, Eigen::Vector3d* g) {
    ++fit.evaluations;
    try {
      const LogMarginalLikelihood r = from_distances(d2, targets, from_log(p));
      if (g != nullptr) *g = -scale * r.gradient;
      return -scale * r.value;
    } catch (const std::runtime_error&) {
      return std::numeric_limits<double>::infinity();
    }
  };

  Random random(options.seed);
  // Start 1: the best point of a coarse scan of length scales (1 % to 100 % of the extent) and
  // noise shares (1 % and 10 % of the RMS), with sigma_f the RMS. Smooth fields surveyed
  // densely have a second optimum at l -> 0 where everything is noise; a start from the wrong
  // side of it never leaves it, so the scan looks at the whole range first.
  Eigen::Vector3d scanned = to_log(initial);
  {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 8; ++i) {
      for (const double noise : {0.01, 0.1}) {
        const Eigen::Vector3d q(std::log(s), std::log(e) + std::log(1e-2) * (1.0 - i / 8.0), std::log(noise * s));
        const double v = evaluate(q, nullptr);
        if (v < best) {
          best = v;
          scanned = q;
        }
      }
    }
  }
  for (int start = 0; start <= options.restarts + 1; ++start) {
    Eigen::Vector3d p = (start == 1 ? scanned : to_log(initial)).cwiseMax(lower).cwiseMin(upper);
    if (start > 1) {
      // Random starts: sigma_f within a decade of the RMS, l between 1 % and 100 % of the extent,
      // sigma_n between 0.1 % and 100 % of sigma_f.
      p(0) = std::log(s) + random.uniform(-1.0, 1.0) * std::log(10.0);
      p(1) = std::log(e) + random.uniform(std::log(1e-2), 0.0);
      p(2) = p(0) + random.uniform(std::log(1e-3), 0.0);
    }
    Eigen::Vector3d g;
    double f = evaluate(p, &g);
    if (!std::isfinite(f)) {
      fit.start_values.push_back(-std::numeric_limits<double>::infinity());
      continue;
    }
    Eigen::Matrix3d h = Eigen::Matrix3d::Identity();  // inverse Hessian estimate
    for (int it = 0; it < options.max_iterations; ++it) {
      if (g.cwiseAbs().maxCoeff() < options.tolerance) break;
      Eigen::Vector3d dir = -h * g;
      if (dir.dot(g) >= 0.0) {  // not a descent direction: restart from steepest descent
        h.setIdentity();
        dir = -g;
      }
      double t = 1.0;
      Eigen::Vector3d next;
      Eigen::Vector3d g_next;
      double f_next = std::numeric_limits<double>::infinity();
      for (int halving = 0; halving < 40; ++halving, t *= 0.5) {
        next = (p + t * dir).cwiseMax(lower).cwiseMin(upper);
        f_next = evaluate(next, &g_next);
        if (std::isfinite(f_next) && f_next <= f + 1e-4 * g.dot(next - p)) break;  // Armijo
      }
      if (!std::isfinite(f_next) || f_next > f) break;  // no progress along any step
      const Eigen::Vector3d step = next - p;
      const Eigen::Vector3d change = g_next - g;
      const double sy = step.dot(change);
      const bool converged = std::abs(f - f_next) <= 1e-12 * (1.0 + std::abs(f)) || step.norm() < 1e-10;
      p = next;
      f = f_next;
      g = g_next;
      if (sy > 1e-12) {  // BFGS update of the inverse Hessian (Nocedal & Wright eq. 6.17)
        if (it == 0) h *= sy / change.squaredNorm();  // the first step's scale (their eq. 6.20)
        const double rho = 1.0 / sy;
        const Eigen::Matrix3d a = Eigen::Matrix3d::Identity() - rho * step * change.transpose();
        h = a * h * a.transpose() + rho * step * step.transpose();
      }
      if (converged) break;
    }
    const double value = -f / scale;
    fit.start_values.push_back(value);
    if (value > fit.log_marginal_likelihood) {
      fit.log_marginal_likelihood = value;
      fit.kernel = from_log(p);
    }
  }
  if (!std::isfinite(fit.log_marginal_likelihood)) {
    throw std::runtime_error("fit_hyperparameters: no start gave a covariance matrix that could be factorised");
  }
  return fit;
}

}  // namespace kiseki
