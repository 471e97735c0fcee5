// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/gp/hyperparameters.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

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

/// K + sigma_n^2 I factorised at one kernel, with what eq. 6.11 and its gradient need. Only the
/// lower triangles of `kf` and `factor` are set (LAPACK reads no more).
struct Factorised {
  SquaredExponential kernel;
  Eigen::MatrixXd kf;      ///< sigma_f^2 exp(-D^2 / 2 l^2), the noise-free kernel matrix
  Eigen::MatrixXd factor;  ///< its Cholesky factor L, then (by gradient()) the inverse
  RowMatrix alpha;         ///< K^-1 Y, row-major: the gradient reads it by rows
  double value = 0.0;      ///< eq. 6.11 summed over Y's columns
};

/// Eq. 6.11 from the inputs' squared distances (computed once per fit); false where K cannot be
/// factorised. Costs one Cholesky factorisation (n^3 / 3).
bool factorise(const Eigen::MatrixXd& d2, const Eigen::Ref<const RowMatrix>& targets, const SquaredExponential& kernel,
               Factorised& out) {
  kernel.validate();
  const Eigen::Index n = d2.rows();
  const Eigen::Index k = targets.cols();
  const double c = -0.5 / (kernel.length_scale * kernel.length_scale);
  const double f2 = kernel.sigma_f * kernel.sigma_f;
  out.kernel = kernel;
  out.kf.setZero(n, n);
  // As kernel_matrix: no subnormal values (see there). The lower triangle only.
#pragma omp parallel for schedule(dynamic, 64) if (n > 500)
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j; i < n; ++i) {
      const double e = d2(i, j) * c;
      out.kf(i, j) = e < -700.0 ? 0.0 : f2 * std::exp(e);
    }
  }
  out.factor = out.kf;
  out.factor.diagonal().array() += kernel.sigma_n * kernel.sigma_n;
  if (!gp_detail::cholesky(out.factor)) return false;
  Eigen::MatrixXd alpha = targets;
  gp_detail::cholesky_solve(out.factor, alpha);
  out.alpha = alpha;
  out.value = -0.5 * (targets.array() * out.alpha.array()).sum() -
              0.5 * static_cast<double>(k) * gp_detail::log_determinant(out.factor) -
              0.5 * static_cast<double>(n * k) * kLog2Pi;
  return true;
}

/// The gradient of eq. 6.11 in (log sigma_f, log l, log sigma_n) at a factorised kernel (two
/// more n^3 / 3 for the inverse). Consumes `f.factor`.
Eigen::Vector3d gradient(Factorised& f, const Eigen::MatrixXd& d2) {
  const Eigen::Index n = d2.rows();
  const auto k = static_cast<double>(f.alpha.cols());
  const double l2 = f.kernel.length_scale * f.kernel.length_scale;
  const double sn2 = f.kernel.sigma_n * f.kernel.sigma_n;
  gp_detail::invert_from_cholesky_lower(f.factor);
  const Eigen::MatrixXd& inv = f.factor;
  // W = alpha alpha^T - k K^-1; dK/dlog sf = 2 Kf (eq. 6.13 x sf), dK/dlog l = Kf D^2 / l^2
  // (eq. 6.14 x l), dK/dlog sn = 2 sn^2 I (eq. 6.15 x sn); each term is 1/2 sum(W o dK), summed
  // here over the lower triangle (off-diagonal terms twice). Per-column partial sums, added in a
  // fixed order afterwards: the same result for any number of threads.
  Eigen::MatrixX3d partial(n, 3);
#pragma omp parallel for schedule(dynamic, 64) if (n > 500)
  for (Eigen::Index j = 0; j < n; ++j) {
    const double wjj = f.alpha.row(j).squaredNorm() - k * inv(j, j);
    double sf = 0.5 * wjj * f.kf(j, j);
    double ls = 0.0;  // D^2 is 0 on the diagonal
    for (Eigen::Index i = j + 1; i < n; ++i) {
      const double w = (f.alpha.row(i).dot(f.alpha.row(j)) - k * inv(i, j)) * f.kf(i, j);
      sf += w;
      ls += w * d2(i, j);
    }
    partial(j, 0) = sf;
    partial(j, 1) = ls;
    partial(j, 2) = wjj;
  }
  return {2.0 * partial.col(0).sum(), partial.col(1).sum() / l2, 0.5 * 2.0 * sn2 * partial.col(2).sum()};
}

/// H g by the two-loop recursion (Nocedal & Wright, Algorithm 7.4) over the stored pairs, with
/// H0 = (s^T y / y^T y) I from the newest pair (their eq. 7.20); g itself without pairs.
Eigen::Vector3d lbfgs_direction(const Eigen::Vector3d& g, const std::vector<Eigen::Vector3d>& steps,
                                const std::vector<Eigen::Vector3d>& changes) {
  Eigen::Vector3d q = g;
  const std::size_t m = steps.size();
  std::vector<double> a(m);
  for (std::size_t i = m; i-- > 0;) {
    a[i] = steps[i].dot(q) / steps[i].dot(changes[i]);
    q -= a[i] * changes[i];
  }
  if (m > 0) q *= steps[m - 1].dot(changes[m - 1]) / changes[m - 1].squaredNorm();
  for (std::size_t i = 0; i < m; ++i) {
    const double b = changes[i].dot(q) / steps[i].dot(changes[i]);
    q += (a[i] - b) * steps[i];
  }
  return q;
}

LogMarginalLikelihood from_distances(const Eigen::MatrixXd& d2, const Eigen::Ref<const RowMatrix>& targets,
                                     const SquaredExponential& kernel) {
  Factorised f;
  if (!factorise(d2, targets, kernel, f)) {
    throw std::runtime_error("log marginal likelihood: K + sigma_n^2 I is not positive definite");
  }
  LogMarginalLikelihood out;
  out.value = f.value;
  out.gradient = gradient(f, d2);
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
  if (!(options.repeat_tolerance >= 0.0) || !(options.repeat_parameter_tolerance >= 0.0)) {
    throw std::invalid_argument("fit_hyperparameters: repeat tolerances must be >= 0");
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
  // f = -LML / (n k), minimised; +inf where K cannot be factorised. A value costs one Cholesky
  // factorisation; its gradient, asked for only at accepted points, two more n^3 / 3.
  Factorised kept;
  const auto value = [&](const Eigen::Vector3d& p) {
    ++fit.evaluations;
    return factorise(d2, targets, from_log(p), kept) ? -scale * kept.value : std::numeric_limits<double>::infinity();
  };
  const auto gradient_of_kept = [&]() -> Eigen::Vector3d {
    ++fit.gradients;
    return -scale * gradient(kept, d2);
  };
  // The gradient with the components that push out of the box at an active bound removed.
  const auto projected = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& g) {
    Eigen::Vector3d out = g;
    for (int i = 0; i < 3; ++i) {
      if ((p(i) <= lower(i) && g(i) > 0.0) || (p(i) >= upper(i) && g(i) < 0.0)) out(i) = 0.0;
    }
    return out;
  };

  Random random(options.seed);
  // Start 1: the best point of a coarse scan of length scales (1 % to 100 % of the extent) and
  // noise shares (1 % and 10 % of the RMS), with sigma_f the RMS; values only. Smooth fields
  // surveyed densely have a second optimum at l -> 0 where everything is noise; a start from the
  // wrong side of it never leaves it, so the scan looks at the whole range first. The data's
  // default start is one of the scan's points and is then not run twice.
  Eigen::Vector3d scanned = to_log(initial);
  if (options.scan) {
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 8; ++i) {
      for (const double noise : {0.01, 0.1}) {
        const Eigen::Vector3d q(std::log(s), std::log(e) + std::log(1e-2) * (1.0 - i / 8.0), std::log(noise * s));
        const double v = value(q);
        if (v < best) {
          best = v;
          scanned = q;
        }
      }
    }
  }
  const bool scan_is_initial = (scanned - to_log(initial)).cwiseAbs().maxCoeff() < 1e-12;
  // Where each start ended (log-parameters, LML), for the stop at a repeated optimum.
  std::vector<std::pair<Eigen::Vector3d, double>> ends;
  const auto repeats_an_earlier_end = [&](const Eigen::Vector3d& p, double lml) {
    for (const auto& [q, v] : ends) {
      if (std::abs(lml - v) <= options.repeat_tolerance * std::max(std::abs(v), 1.0) &&
          (p - q).cwiseAbs().maxCoeff() <= options.repeat_parameter_tolerance) {
        return true;
      }
    }
    return false;
  };
  for (int start = 0; start <= options.restarts + 1; ++start) {
    if (start == 1 && scan_is_initial) continue;
    Eigen::Vector3d p = (start == 1 ? scanned : to_log(initial)).cwiseMax(lower).cwiseMin(upper);
    if (start > 1) {
      // Random starts: sigma_f within a decade of the RMS, l between 1 % and 100 % of the extent,
      // sigma_n between 0.1 % and 100 % of sigma_f.
      p(0) = std::log(s) + random.uniform(-1.0, 1.0) * std::log(10.0);
      p(1) = std::log(e) + random.uniform(std::log(1e-2), 0.0);
      p(2) = p(0) + random.uniform(std::log(1e-3), 0.0);
      p = p.cwiseMax(lower).cwiseMin(upper);
    }
    double f = value(p);
    if (!std::isfinite(f)) {
      fit.start_values.push_back(-std::numeric_limits<double>::infinity());
      continue;
    }
    Eigen::Vector3d g = gradient_of_kept();
    // Projected L-BFGS (Nocedal & Wright, Algorithm 7.4 and the two-loop recursion of their
    // Algorithm 7.5, the last kMemory steps, the initial inverse Hessian rescaled at every
    // iteration by their eq. 7.20) with the box by projection; a backtracking line search on
    // values alone (their Algorithm 3.1 with the quadratic interpolation of their eq. 3.57); and
    // L-BFGS-B's stopping rules: a relative decrease of at most function_tolerance, or a
    // projected gradient below tolerance. The rescaling matters here: a random start far out
    // has gradients 1e6 times those near the optimum, and plain BFGS keeps the first scale.
    constexpr std::size_t kMemory = 10;  // L-BFGS-B's default m
    std::vector<Eigen::Vector3d> steps;
    std::vector<Eigen::Vector3d> changes;
    for (int it = 0; it < options.max_iterations; ++it) {
      if (projected(p, g).cwiseAbs().maxCoeff() < options.tolerance) break;
      Eigen::Vector3d dir = -lbfgs_direction(g, steps, changes);
      for (int i = 0; i < 3; ++i) {  // no steps out of the box at an active bound
        if ((p(i) <= lower(i) && dir(i) < 0.0) || (p(i) >= upper(i) && dir(i) > 0.0)) dir(i) = 0.0;
      }
      if (dir.dot(g) >= 0.0) {  // not a descent direction: steepest descent, forget the curvature
        steps.clear();
        changes.clear();
        dir = -projected(p, g);
      }
      // Without curvature pairs the first step is at most 1 long in log-parameters (a factor
      // e), as L-BFGS-B's.
      double t = steps.empty() ? std::min(1.0, 1.0 / dir.norm()) : 1.0;
      Eigen::Vector3d next;
      double f_next = std::numeric_limits<double>::infinity();
      bool accepted = false;
      for (int trial = 0; trial < 30; ++trial) {
        next = (p + t * dir).cwiseMax(lower).cwiseMin(upper);
        const double slope = g.dot(next - p);  // < 0 along a descent direction
        f_next = value(next);
        if (std::isfinite(f_next) && f_next <= f + 1e-4 * slope) {
          accepted = true;
          break;
        }
        // The minimum of the quadratic through f, its slope and f_next, kept within [0.1, 0.5] t.
        const double curvature = f_next - f - slope;
        double shrink = 0.25;
        if (std::isfinite(f_next) && curvature > 0.0) shrink = std::clamp(-0.5 * slope / curvature, 0.1, 0.5);
        t *= shrink;
      }
      if (!accepted) break;  // no decrease along this direction: as far as this start goes
      const Eigen::Vector3d g_next = gradient_of_kept();
      const Eigen::Vector3d step = next - p;
      const Eigen::Vector3d change = g_next - g;
      const bool converged =
          (f - f_next) <= options.function_tolerance * std::max({std::abs(f), std::abs(f_next), 1.0});
      p = next;
      f = f_next;
      g = g_next;
      if (step.dot(change) > 1e-10 * step.norm() * change.norm()) {  // keep pairs with curvature
        if (steps.size() == kMemory) {
          steps.erase(steps.begin());
          changes.erase(changes.begin());
        }
        steps.push_back(step);
        changes.push_back(change);
      }
      if (converged) break;
    }
    const double lml = -f / scale;
    fit.start_values.push_back(lml);
    if (lml > fit.log_marginal_likelihood) {
      fit.log_marginal_likelihood = lml;
      fit.kernel = from_log(p);
    }
    const bool repeated = repeats_an_earlier_end(p, lml);
    if (options.stop_at_repeat && repeated) break;
    ends.emplace_back(p, lml);
    if (!repeated) fit.optima.emplace_back(from_log(p), lml);
  }
  if (!std::isfinite(fit.log_marginal_likelihood)) {
    throw std::runtime_error("fit_hyperparameters: no start gave a covariance matrix that could be factorised");
  }
  return fit;
}

}  // namespace kiseki
