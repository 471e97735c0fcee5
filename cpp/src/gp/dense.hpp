// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// Private to kiseki/gp: the dense factorisations and products of the Gaussian processes, done by
// LAPACK and BLAS (OpenBLAS on Debian, vectorised for the CPU it runs on; tiled over OpenMP's
// threads so that the result does not depend on their number, see dense.cpp), on
// column-major Eigen matrices.
#pragma once

#include <Eigen/Core>

namespace kiseki::gp_detail {

/// In place: a symmetric positive definite matrix -> its lower Cholesky factor L (the upper
/// triangle is zeroed). Returns false when the matrix is not positive definite.
bool cholesky(Eigen::MatrixXd& a);
/// From L: the full inverse (L L^T)^-1, symmetric.
Eigen::MatrixXd inverse_from_cholesky(const Eigen::MatrixXd& l);
/// In place, the lower triangle only (the upper is left as it was).
void invert_from_cholesky_lower(Eigen::MatrixXd& l);
/// In place: b <- (L L^T)^-1 b.
void cholesky_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b);
/// In place: b <- L^-1 b.
void lower_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b);
/// a^T a (symmetric, both triangles filled).
Eigen::MatrixXd gram(const Eigen::MatrixXd& a);
/// a b.
Eigen::MatrixXd multiply(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);
/// log det (L L^T) = 2 sum log L_ii.
double log_determinant(const Eigen::MatrixXd& l);
/// The Cholesky factor of a + jitter I with the smallest jitter in 0, 1e-10 s, 1e-9 s, ...,
/// 1e-4 s (s = mean diagonal) that makes it positive definite; the jitter used goes to *jitter.
/// Throws std::runtime_error when none does.
Eigen::MatrixXd cholesky_with_jitter(const Eigen::MatrixXd& a, double* jitter, const char* what);

}  // namespace kiseki::gp_detail
