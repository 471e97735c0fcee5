// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "dense.hpp"

#include <cblas.h>
#include <lapacke.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kiseki::gp_detail {

// LAPACKE's *_work entry points: the plain ones first scan the whole matrix for NaN (an O(n^2)
// pass per call, 2 % of a hyperparameter fit); kiseki's matrices are built from inputs checked
// to be finite, and a NaN reaching dpotrf still fails its positive-definiteness test.

namespace {
lapack_int checked_size(Eigen::Index n) {
  if (n > std::numeric_limits<lapack_int>::max()) throw std::length_error("matrix too large for LAPACK");
  return static_cast<lapack_int>(n);
}
}  // namespace

bool cholesky(Eigen::MatrixXd& a) {
  const lapack_int n = checked_size(a.rows());
  if (n == 0) return true;
  const lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, a.data(), n);
  if (info != 0) return false;
  a.triangularView<Eigen::StrictlyUpper>().setZero();
  return true;
}

Eigen::MatrixXd inverse_from_cholesky(const Eigen::MatrixXd& l) {
  Eigen::MatrixXd inv = l;
  const lapack_int n = checked_size(l.rows());
  if (n == 0) return inv;
  if (LAPACKE_dpotri_work(LAPACK_COL_MAJOR, 'L', n, inv.data(), n) != 0) {
    throw std::runtime_error("Gaussian process: the covariance matrix could not be inverted");
  }
  inv.triangularView<Eigen::StrictlyUpper>() = inv.transpose();
  return inv;
}

void invert_from_cholesky_lower(Eigen::MatrixXd& l) {
  const lapack_int n = checked_size(l.rows());
  if (n == 0) return;
  if (LAPACKE_dpotri_work(LAPACK_COL_MAJOR, 'L', n, l.data(), n) != 0) {
    throw std::runtime_error("Gaussian process: the covariance matrix could not be inverted");
  }
}

void cholesky_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b) {
  const lapack_int n = checked_size(l.rows());
  if (n == 0 || b.cols() == 0) return;
  LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, checked_size(b.cols()), l.data(), n, b.data(), n);
}

void lower_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b) {
  const auto n = checked_size(l.rows());
  if (n == 0 || b.cols() == 0) return;
  cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, n, checked_size(b.cols()), 1.0,
              l.data(), n, b.data(), checked_size(b.rows()));
}

Eigen::MatrixXd gram(const Eigen::MatrixXd& a) {
  const auto n = checked_size(a.cols());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
  if (n == 0 || a.rows() == 0) return g;
  cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, n, checked_size(a.rows()), 1.0, a.data(),
              checked_size(a.rows()), 0.0, g.data(), n);
  g.triangularView<Eigen::StrictlyUpper>() = g.transpose();
  return g;
}

Eigen::MatrixXd multiply(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.cols() != b.rows()) throw std::invalid_argument("multiply: inner dimensions differ");
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(a.rows(), b.cols());
  if (a.rows() == 0 || b.cols() == 0 || a.cols() == 0) return c;
  cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, checked_size(a.rows()), checked_size(b.cols()),
              checked_size(a.cols()), 1.0, a.data(), checked_size(a.rows()), b.data(), checked_size(b.rows()), 0.0,
              c.data(), checked_size(c.rows()));
  return c;
}

double log_determinant(const Eigen::MatrixXd& l) { return 2.0 * l.diagonal().array().log().sum(); }

Eigen::MatrixXd cholesky_with_jitter(const Eigen::MatrixXd& a, double* jitter, const char* what) {
  const double scale = a.rows() > 0 ? a.diagonal().mean() : 1.0;
  for (int k = -1; k <= 6; ++k) {
    const double j = k < 0 ? 0.0 : scale * std::pow(10.0, -10 + k);
    Eigen::MatrixXd l = a;
    l.diagonal().array() += j;
    if (cholesky(l)) {
      if (jitter != nullptr) *jitter = j;
      return l;
    }
  }
  throw std::runtime_error(std::string(what) +
                           ": the covariance matrix is not positive definite even with a jitter of 1e-4 of its "
                           "diagonal (duplicate inputs with a tiny noise, or badly scaled data?)");
}

}  // namespace kiseki::gp_detail
