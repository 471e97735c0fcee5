// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <cblas.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "kiseki/core/random.hpp"
#include "kiseki/gp/hilbert_gp.hpp"
#include "kiseki/gp/hyperparameters.hpp"
#include "kiseki/models/magnetic_map_model.hpp"

namespace kiseki {
namespace {

RowMatrix uniform_points(Eigen::Index n, Eigen::Index d, double size, std::uint64_t seed) {
  Random r(seed);
  RowMatrix x(n, d);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index c = 0; c < d; ++c) x(i, c) = r.uniform(0.0, size);
  return x;
}

RowMatrix smooth_field(const RowMatrix& x, double noise, std::uint64_t seed) {
  Random r(seed);
  RowMatrix y(x.rows(), 2);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double a = x(i, 0);
    const double b = x.cols() > 1 ? x(i, 1) : 0.0;
    y(i, 0) = std::sin(1.3 * a) * std::cos(0.7 * b) + r.normal(0.0, noise);
    y(i, 1) = 0.5 * a - std::cos(b) + r.normal(0.0, noise);
  }
  return y;
}

// The textbook formulas with Eigen's own LLT, every training point: the reference.
void brute_force(const RowMatrix& x, const RowMatrix& y, const SquaredExponential& k, const RowMatrix& q,
                 Eigen::MatrixXd& mean, Eigen::VectorXd& var) {
  Eigen::MatrixXd cov = kernel_matrix(k, x, x);
  cov.diagonal().array() += k.sigma_n * k.sigma_n;
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  const Eigen::MatrixXd ks = kernel_matrix(k, q, x);
  mean = ks * llt.solve(Eigen::MatrixXd(y));
  const Eigen::MatrixXd v = llt.matrixL().solve(ks.transpose());
  var = (k.sigma_f * k.sigma_f - v.colwise().squaredNorm().array()).matrix().transpose();
}

TEST(ExactGp, MatchesTheTextbookFormulas) {
  const RowMatrix x = uniform_points(200, 2, 3.0, 1);
  const RowMatrix y = smooth_field(x, 0.05, 2);
  const SquaredExponential k{1.2, 0.6, 0.05};
  const ExactGaussianProcess gp(x, y, k, GpMean::zero);
  const RowMatrix q = uniform_points(300, 2, 3.5, 3);
  RowMatrix mean;
  Eigen::VectorXd var;
  gp.predict(q, mean, &var);
  Eigen::MatrixXd ref_mean;
  Eigen::VectorXd ref_var;
  brute_force(x, y, k, q, ref_mean, ref_var);
  EXPECT_LT((mean - ref_mean).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((var - ref_var).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ExactGp, TruncatedBlocksAgreeWithEveryPoint) {
  // 2,500 points (above the dense limit) over 20 x 20 m with l = 0.5 m: blocks use only the
  // training points within the cutoff radius.
  const RowMatrix x = uniform_points(2500, 2, 20.0, 4);
  const RowMatrix y = smooth_field(x, 0.05, 5);
  const ExactGaussianProcess gp(x, y, {1.0, 0.5, 0.1}, GpMean::constant);
  const RowMatrix q = uniform_points(1500, 2, 20.0, 6);
  RowMatrix m1, m0;
  Eigen::VectorXd v1, v0;
  gp.predict(q, m1, &v1);
  gp.predict(q, m0, &v0, 0.0);
  EXPECT_LT((m1 - m0).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((v1 - v0).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ExactGp, LogMarginalLikelihoodGradientMatchesFiniteDifferences) {
  const RowMatrix x = uniform_points(80, 3, 2.0, 7);
  RowMatrix y = smooth_field(x, 0.1, 8);
  const SquaredExponential k{0.9, 0.4, 0.2};
  const LogMarginalLikelihood r = log_marginal_likelihood(x, y, k);
  const ExactGaussianProcess gp(x, y, k, GpMean::zero);
  EXPECT_NEAR(r.value, gp.log_marginal_likelihood(), 1e-8 * std::abs(r.value));
  const double h = 1e-6;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d p(std::log(k.sigma_f), std::log(k.length_scale), std::log(k.sigma_n));
    Eigen::Vector3d q = p;
    p(j) += h;
    q(j) -= h;
    const double up = log_marginal_likelihood(x, y, {std::exp(p(0)), std::exp(p(1)), std::exp(p(2))}).value;
    const double down = log_marginal_likelihood(x, y, {std::exp(q(0)), std::exp(q(1)), std::exp(q(2))}).value;
    EXPECT_NEAR(r.gradient(j), (up - down) / (2 * h), 1e-5 * (1.0 + std::abs(r.gradient(j))));
  }
}

TEST(ExactGp, HyperparametersOfASampledFieldAreFound) {
  // A field drawn from the GP prior itself (sigma_f 1, l 0.5, sigma_n 0.1), 400 points.
  const SquaredExponential truth{1.0, 0.5, 0.1};
  const RowMatrix x = uniform_points(400, 2, 4.0, 9);
  Eigen::MatrixXd cov = kernel_matrix(truth, x, x);
  cov.diagonal().array() += truth.sigma_n * truth.sigma_n + 1e-10;
  const Eigen::MatrixXd l = Eigen::LLT<Eigen::MatrixXd>(cov).matrixL();
  Random r(10);
  Eigen::VectorXd z(400);
  for (auto& v : z) v = r.normal();
  const RowMatrix y = l * z;
  const HyperparameterFit fit = fit_hyperparameters(x, y, initial_kernel(x, y));
  EXPECT_NEAR(fit.kernel.length_scale, truth.length_scale, 0.15);
  EXPECT_NEAR(fit.kernel.sigma_n, truth.sigma_n, 0.03);
  EXPECT_GE(fit.log_marginal_likelihood, log_marginal_likelihood(x, y, truth).value);
  // The same seed gives the same answer.
  const HyperparameterFit again = fit_hyperparameters(x, y, initial_kernel(x, y));
  EXPECT_EQ(fit.kernel.length_scale, again.kernel.length_scale);
  // Every start made (no stop at a repeat): the optima list each distinct end once (no two
  // within the repeat tolerances of each other), the best among them.
  HyperparameterOptions all;
  all.stop_at_repeat = false;
  const HyperparameterFit every = fit_hyperparameters(x, y, initial_kernel(x, y), all);
  ASSERT_FALSE(every.optima.empty());
  EXPECT_LE(every.optima.size(), every.start_values.size());
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < every.optima.size(); ++i) {
    best = std::max(best, every.optima[i].second);
    for (std::size_t j = 0; j < i; ++j) {
      const auto& [a, va] = every.optima[i];
      const auto& [b, vb] = every.optima[j];
      const bool same_value = std::abs(va - vb) <= all.repeat_tolerance * std::max(std::abs(vb), 1.0);
      const bool same_place = std::abs(std::log(a.sigma_f / b.sigma_f)) <= all.repeat_parameter_tolerance &&
                              std::abs(std::log(a.length_scale / b.length_scale)) <= all.repeat_parameter_tolerance &&
                              std::abs(std::log(a.sigma_n / b.sigma_n)) <= all.repeat_parameter_tolerance;
      EXPECT_FALSE(same_value && same_place) << "optima " << j << " and " << i;
    }
  }
  // a repeated end may be the best by less than the repeat tolerance
  EXPECT_NEAR(best, every.log_marginal_likelihood, all.repeat_tolerance * std::abs(best));
  HyperparameterOptions bad;
  bad.repeat_tolerance = -1e-6;
  EXPECT_THROW(fit_hyperparameters(x, y, initial_kernel(x, y), bad), std::invalid_argument);
}

TEST(ExactGp, SameBitsOnAnyThreadCount) {
  // 700 points: three tiles of the dense algebra, so the factorisation, the inverse of the
  // gradient and the products are spread over the threads, and 2,500 prediction points in three
  // blocks, which predict spreads; OpenBLAS is asked for as many
  // threads of its own, which the GP must not use (its splits change the last bits).
  const RowMatrix x = uniform_points(700, 2, 6.0, 21);
  const RowMatrix y = smooth_field(x, 0.05, 22);
  const RowMatrix q = uniform_points(2500, 2, 6.0, 23);  // three blocks of prediction points
  auto run = [&](int threads) {
    omp_set_num_threads(threads);
    openblas_set_num_threads(threads);
    const HyperparameterFit fit = fit_hyperparameters(x, y, initial_kernel(x, y));
    const ExactGaussianProcess gp(x, y, fit.kernel);
    RowMatrix mean;
    Eigen::VectorXd var;
    gp.predict(q, mean, &var);
    return std::make_tuple(fit.kernel.sigma_f, fit.kernel.length_scale, fit.kernel.sigma_n,
                           fit.log_marginal_likelihood, Eigen::MatrixXd(mean), Eigen::VectorXd(var));
  };
  const int saved = omp_get_max_threads();
  const auto one = run(1);
  for (int threads : {2, 3}) {
    const auto other = run(threads);
    EXPECT_EQ(std::get<0>(one), std::get<0>(other)) << threads;
    EXPECT_EQ(std::get<1>(one), std::get<1>(other)) << threads;
    EXPECT_EQ(std::get<2>(one), std::get<2>(other)) << threads;
    EXPECT_EQ(std::get<3>(one), std::get<3>(other)) << threads;
    EXPECT_TRUE((std::get<4>(one).array() == std::get<4>(other).array()).all()) << threads;
    EXPECT_TRUE((std::get<5>(one).array() == std::get<5>(other).array()).all()) << threads;
  }
  omp_set_num_threads(saved);
}

TEST(HilbertGp, ApproachesTheExactGp) {
  const RowMatrix x = uniform_points(600, 2, 4.0, 11);
  const RowMatrix y = smooth_field(x, 0.05, 12);
  const SquaredExponential k{1.0, 0.7, 0.05};
  const ExactGaussianProcess exact(x, y, k, GpMean::constant);
  const HilbertGaussianProcess hilbert(x, y, k, Eigen::Vector2d(-2.0, -2.0), Eigen::Vector2d(6.0, 6.0), 1e-6);
  const RowMatrix q = uniform_points(400, 2, 4.0, 13);
  RowMatrix me, mh;
  Eigen::VectorXd ve, vh;
  exact.predict(q, me, &ve);
  hilbert.predict(q, mh, &vh);
  EXPECT_LT((me - mh).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_LT((ve - vh).cwiseAbs().maxCoeff(), 2e-3);
  // Outside the domain: the prior.
  RowMatrix out(1, 2);
  out << 10.0, 10.0;
  hilbert.predict(out, mh, &vh);
  EXPECT_DOUBLE_EQ(vh(0), 1.0);
  EXPECT_DOUBLE_EQ(mh(0, 0), hilbert.prior_mean()(0));
}

TEST(Gp, RefusesBadInput) {
  const RowMatrix x = uniform_points(10, 2, 1.0, 14);
  const RowMatrix y = smooth_field(x, 0.0, 15);
  const SquaredExponential k{1.0, 0.5, 0.1};
  EXPECT_THROW(ExactGaussianProcess(x.topRows(2), y.topRows(2), k), std::invalid_argument);  // n <= d
  EXPECT_THROW(ExactGaussianProcess(x, y.topRows(9), k), std::invalid_argument);             // lengths
  RowMatrix nan = y;
  nan(3, 1) = std::nan("");
  EXPECT_THROW(ExactGaussianProcess(x, nan, k), std::invalid_argument);
  const RowMatrix same = RowMatrix::Constant(10, 2, 1.5);
  EXPECT_THROW(ExactGaussianProcess(same, y, k), std::invalid_argument);
  EXPECT_THROW(ExactGaussianProcess(x, y, {1.0, -1.0, 0.1}), std::invalid_argument);
  EXPECT_THROW(HilbertGaussianProcess(x, y, k, Eigen::Vector2d(0.2, 0.2), Eigen::Vector2d(2.0, 2.0)),
               std::invalid_argument);  // points outside the domain
}

MagneticGrid linear_grid() {
  MagneticGrid g;
  g.origin_x = -1.0;
  g.origin_y = 2.0;
  g.resolution = 0.5;
  g.width = 8;
  g.height = 6;
  for (int j = 0; j < g.height; ++j) {
    for (int i = 0; i < g.width; ++i) {
      const double x = g.origin_x + (i + 0.5) * g.resolution;
      const double y = g.origin_y + (j + 0.5) * g.resolution;
      for (double v : {0.2 + 0.1 * x, -0.1 + 0.05 * y, 0.4 + 0.02 * x - 0.03 * y}) g.mean.push_back(v);
      for (int c = 0; c < 3; ++c) g.variance.push_back(0.001 * (c + 1));
    }
  }
  g.prior_mean = Eigen::Vector3d(0.2, -0.1, 0.4);
  g.prior_variance = Eigen::Vector3d(0.01, 0.01, 0.01);
  return g;
}

TEST(MagneticMapModel, InterpolatesAndFallsBackToThePrior) {
  const MagneticGrid g = linear_grid();
  Eigen::Vector3d mu, var;
  g.value_at(0.33, 3.1, mu, var);  // inside the cell centres: bilinear = the linear field
  EXPECT_NEAR(mu(0), 0.2 + 0.033, 1e-12);
  EXPECT_NEAR(mu(1), -0.1 + 0.155, 1e-12);
  EXPECT_NEAR(mu(2), 0.4 + 0.02 * 0.33 - 0.03 * 3.1, 1e-12);
  EXPECT_NEAR(var(2), 0.003, 1e-15);
  g.value_at(50.0, 3.0, mu, var);
  EXPECT_EQ(mu, g.prior_mean);
  EXPECT_EQ(var, g.prior_variance);
}

TEST(MagneticMapModel, LikelihoodIsEq617AndPrefersTheTrueHeading) {
  MagneticGrid g = linear_grid();
  const MagneticMapModel model(g, {Eigen::Vector2d(0.2, 0.0), Eigen::Vector2d(-0.2, 0.1)}, 0.01);
  MagneticMapModel m = model;
  const Pose2 truth{0.5, 3.2, 0.7};
  // The readings the sensors would give at the true pose, in the body frame.
  std::vector<Eigen::Vector3d> z;
  for (const Eigen::Vector2d& o : {Eigen::Vector2d(0.2, 0.0), Eigen::Vector2d(-0.2, 0.1)}) {
    const double c = std::cos(truth.theta), s = std::sin(truth.theta);
    Eigen::Vector3d mu, var;
    g.value_at(truth.x + c * o.x() - s * o.y(), truth.y + s * o.x() + c * o.y(), mu, var);
    z.emplace_back(c * mu.x() + s * mu.y(), -s * mu.x() + c * mu.y(), mu.z());
  }
  m.set_readings(z);
  const Pose2 poses[3] = {truth, {0.5, 3.2, 0.7 + 1.5}, {1.5, 3.2, 0.7}};
  double out[3];
  m.log_likelihoods(poses, 3, out);
  double expected = 0.0;
  for (int i = 0; i < 2; ++i)
    for (int c = 0; c < 3; ++c) expected += -0.5 * std::log(2 * M_PI * (0.001 * (c + 1) + 1e-4));
  EXPECT_NEAR(out[0], expected, 1e-9);
  EXPECT_GT(out[0], out[1]);
  EXPECT_GT(out[0], out[2]);
  EXPECT_THROW(m.set_readings({z[0]}), std::invalid_argument);
}

}  // namespace
}  // namespace kiseki
