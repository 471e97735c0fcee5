// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "kiseki/gp/exact_gp.hpp"

namespace kiseki {

/// log p(Y | X, theta) (thesis eq. 6.11, summed over Y's columns) and its gradient with respect to
/// (log sigma_f, log l, log sigma_n).
///
/// The gradient is Rasmussen & Williams' eq. 5.9, 1/2 tr((alpha alpha^T - K^-1) dK/dtheta), with
/// the kernel derivatives of eqs. 6.13-6.15 times theta (the chain rule for log-parameters). The
/// thesis' eq. 6.12 prints only the alpha alpha^T term; without -K^-1 the gradient is not that of
/// eq. 6.11, so kiseki uses the complete form.
struct LogMarginalLikelihood {
  double value = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
};

/// Targets are used as given (remove a mean first if the model has one). Throws
/// std::runtime_error when K + sigma_n^2 I cannot be factorised.
LogMarginalLikelihood log_marginal_likelihood(const Eigen::Ref<const RowMatrix>& inputs,
                                              const Eigen::Ref<const RowMatrix>& targets,
                                              const SquaredExponential& kernel);

struct HyperparameterOptions {
  int restarts = 3;           ///< random starts after the first (at most; see stop_at_repeat)
  /// The random starts stop once a start ends where an earlier one ended (the same log marginal
  /// likelihood to repeat_tolerance of its size and every log-parameter within
  /// repeat_parameter_tolerance): a second arrival at one optimum from another start is what
  /// the restarts are run to learn, and every further start costs as much as the first.
  bool stop_at_repeat = true;
  double repeat_tolerance = 1e-6;
  double repeat_parameter_tolerance = 0.01;  ///< in log-parameters: 1 % of each value
  std::uint64_t seed = 0;     ///< for the random starts
  int max_iterations = 100;   ///< BFGS iterations per start
  /// The coarse scan as a start (18 values). Off for a refinement from a start known to be near
  /// the optimum (a subsample's), where the scan's values on every reading would cost the most.
  bool scan = true;
  double tolerance = 1e-6;    ///< on the largest projected gradient component of LML / (n k)
  /// A start stops when an iteration lowers -LML by at most this share of its size: factr x
  /// machine epsilon with L-BFGS-B's default factr of 1e7 (the setting scikit-learn uses).
  double function_tolerance = 1e7 * 2.220446049250313e-16;
};

struct HyperparameterFit {
  SquaredExponential kernel;
  double log_marginal_likelihood = 0.0;
  int evaluations = 0;                  ///< likelihood values (one Cholesky factorisation each), all starts
  int gradients = 0;                    ///< of which also with the gradient (the inverse as well)
  std::vector<double> start_values;     ///< the best LML reached from each start made
  /// Where the starts ended that did not end at an earlier start's optimum, in the order
  /// reached, with their LML: the distinct optima found (a coarse search's candidates).
  std::vector<std::pair<SquaredExponential, double>> optima;
};

/// Maximises eq. 6.11 over (sigma_f, l, sigma_n) by projected BFGS in log-parameters with a
/// backtracking line search on likelihood values (the gradient only at accepted points), from
/// `initial`, from the best point of a coarse scan of length scales and noise levels (18 values;
/// skipped as a start when it is `initial`; not made without `options.scan`), and from up to `restarts` random starts
/// (log-uniform within the bounds below, drawn from kiseki::Random(seed); with
/// `options.stop_at_repeat`, none after a start that ends at an earlier start's optimum); the best start wins. Bounds, from the
/// data: sigma_f and sigma_n in [1e-6, 1e3] x the targets' RMS, l in [1e-3, 1e2] x the inputs'
/// largest extent. Targets are used as given (remove a mean first).
HyperparameterFit fit_hyperparameters(const Eigen::Ref<const RowMatrix>& inputs,
                                      const Eigen::Ref<const RowMatrix>& targets,
                                      const SquaredExponential& initial, const HyperparameterOptions& options = {});

/// A starting point from the data: sigma_f the targets' RMS, l a tenth of the inputs' largest
/// extent, sigma_n a tenth of sigma_f.
SquaredExponential initial_kernel(const Eigen::Ref<const RowMatrix>& inputs, const Eigen::Ref<const RowMatrix>& targets);

}  // namespace kiseki
