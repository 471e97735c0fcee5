// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The Gaussian processes' tiled dense algebra (private to kiseki/gp) against Eigen's own
// (references computed another way), and the same bits for any number of threads.
#include <cblas.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cstring>
#include <functional>
#include <vector>

#include "gp/dense.hpp"
#include "kiseki/core/random.hpp"

namespace {

using Eigen::MatrixXd;
using kiseki::gp_detail::cholesky;

MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, std::uint64_t seed) {
  kiseki::Random rng(seed);
  MatrixXd m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j) {
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = rng.normal(0.0, 1.0);
  }
  return m;
}

MatrixXd random_spd(Eigen::Index n, std::uint64_t seed) {
  const MatrixXd a = random_matrix(n, n, seed);
  MatrixXd k = a * a.transpose() / static_cast<double>(n);
  k.diagonal().array() += 0.1;  // well conditioned enough to compare to 1e-9
  return k;
}

bool same_bits(const MatrixXd& a, const MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// Sizes around the tiles' 256: one tile, one tile and a row, several with a short last one.
const std::vector<Eigen::Index> kSizes = {1, 5, 255, 256, 257, 600};

TEST(GpDense, CholeskyMatchesEigensFactor) {
  for (Eigen::Index n : kSizes) {
    const MatrixXd k = random_spd(n, 10 + static_cast<std::uint64_t>(n));
    MatrixXd l = k;
    ASSERT_TRUE(cholesky(l)) << n;
    const MatrixXd reference = k.llt().matrixL();
    EXPECT_LT((l - reference).cwiseAbs().maxCoeff(), 1e-10) << n;
    EXPECT_EQ(l.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0) << n;
  }
}

TEST(GpDense, RefusesAMatrixThatIsNotPositiveDefinite) {
  for (Eigen::Index n : {Eigen::Index{3}, Eigen::Index{700}}) {
    MatrixXd k = random_spd(n, 3);
    k(n - 1, n - 1) = -1.0;  // the last pivot, in the last tile, goes negative
    EXPECT_FALSE(cholesky(k)) << n;
  }
}

TEST(GpDense, InverseMatchesEigensInverse) {
  for (Eigen::Index n : kSizes) {
    const MatrixXd k = random_spd(n, 20 + static_cast<std::uint64_t>(n));
    MatrixXd l = k;
    ASSERT_TRUE(cholesky(l));
    const MatrixXd inv = kiseki::gp_detail::inverse_from_cholesky(l);
    const MatrixXd reference = k.llt().solve(MatrixXd::Identity(n, n));
    EXPECT_LT((inv - reference).cwiseAbs().maxCoeff(), 1e-9 * reference.cwiseAbs().maxCoeff()) << n;
    // the lower-triangle form leaves the upper triangle as it was
    MatrixXd lower = l;
    lower.triangularView<Eigen::StrictlyUpper>().setConstant(7.0);
    kiseki::gp_detail::invert_from_cholesky_lower(lower);
    EXPECT_TRUE(same_bits(lower.triangularView<Eigen::Lower>().toDenseMatrix(),
                          inv.triangularView<Eigen::Lower>().toDenseMatrix()))
        << n;
    if (n > 1) {
      EXPECT_EQ(lower(0, n - 1), 7.0);
    }
  }
}

TEST(GpDense, ProductsAndSolvesMatchEigen) {
  const MatrixXd k = random_spd(600, 5);
  MatrixXd l = k;
  ASSERT_TRUE(cholesky(l));
  const MatrixXd b = random_matrix(600, 300, 6);
  MatrixXd x = b;
  kiseki::gp_detail::cholesky_solve(l, x);
  EXPECT_LT((k * x - b).cwiseAbs().maxCoeff(), 1e-9);
  MatrixXd y = b;
  kiseki::gp_detail::lower_solve(l, y);
  EXPECT_LT((l * y - b).cwiseAbs().maxCoeff(), 1e-9);
  const MatrixXd a = random_matrix(700, 530, 7);
  EXPECT_LT((kiseki::gp_detail::gram(a) - a.transpose() * a).cwiseAbs().maxCoeff(), 1e-9);
  const MatrixXd c = random_matrix(530, 3, 8);
  EXPECT_LT((kiseki::gp_detail::multiply(a, c) - a * c).cwiseAbs().maxCoeff(), 1e-10);
}

// Each operation on 1 OpenMP thread, then on 2 and 3 with OpenBLAS asked for 1 or 2 of its own
// threads before (the library must run it on the calling thread either way): the same bits.
TEST(GpDense, SameBitsForAnyThreadCount) {
  const MatrixXd k = random_spd(600, 11);
  const MatrixXd b = random_matrix(600, 300, 12);
  const MatrixXd a = random_matrix(700, 530, 13);
  const std::vector<std::function<MatrixXd()>> ops = {
      [&] {
        MatrixXd l = k;
        EXPECT_TRUE(cholesky(l));
        return l;
      },
      [&] {
        MatrixXd l = k;
        EXPECT_TRUE(cholesky(l));
        return kiseki::gp_detail::inverse_from_cholesky(l);
      },
      [&] {
        MatrixXd l = k, x = b;
        EXPECT_TRUE(cholesky(l));
        kiseki::gp_detail::cholesky_solve(l, x);
        kiseki::gp_detail::lower_solve(l, x);
        return x;
      },
      [&] { return kiseki::gp_detail::gram(a); },
      [&] { return kiseki::gp_detail::multiply(b.transpose(), k); },
  };
  const int saved = omp_get_max_threads();
  for (std::size_t o = 0; o < ops.size(); ++o) {
    omp_set_num_threads(1);
    openblas_set_num_threads(1);
    const MatrixXd one = ops[o]();
    for (int threads : {2, 3}) {
      for (int blas : {1, 2}) {
        omp_set_num_threads(threads);
        openblas_set_num_threads(blas);
        EXPECT_TRUE(same_bits(ops[o](), one)) << "operation " << o << ", threads " << threads << ", blas " << blas;
      }
    }
  }
  omp_set_num_threads(saved);
}

}  // namespace
