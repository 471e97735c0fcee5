// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "dense.hpp"

#include <cblas.h>
#include <lapacke.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace kiseki::gp_detail {

// LAPACKE's *_work entry points: the plain ones first scan the whole matrix for NaN (an O(n^2)
// pass per call, 2 % of a hyperparameter fit); kiseki's matrices are built from inputs checked
// to be finite, and a NaN reaching dpotrf still fails its positive-definiteness test.
//
// The same result for any thread count. OpenBLAS splits its own work differently for one and for
// two threads, so that its dgemm, dpotrf and dpotri then differ in the last bits (measured with
// Debian's 0.3.21; its dsyrk and dtrsm did not). Here OpenBLAS runs every call on the calling
// thread, and the large operations are cut into tiles of kTile rows and columns spread over
// OpenMP's threads: each tile is computed by one thread, by the same BLAS calls in the same
// order whichever thread takes it, so the result depends on the matrices only. The tiled
// Cholesky factorisation and inverse are LAPACK's blocked algorithms (dpotrf, then dtrtri and
// dlauum for dpotri) with the block operations on tiles (Buttari et al., "A class of parallel
// tiled linear algebra algorithms for multicore architectures", Parallel Computing 35, 2009).

namespace {

constexpr lapack_int kTile = 256;

lapack_int checked_size(Eigen::Index n) {
  if (n > std::numeric_limits<lapack_int>::max()) throw std::length_error("matrix too large for LAPACK");
  return static_cast<lapack_int>(n);
}

// Set on every call (a read when it holds already): whatever asked OpenBLAS for threads since.
void blas_on_the_calling_thread() {
  if (openblas_get_num_threads() != 1) openblas_set_num_threads(1);
}

/// task(0), ..., task(count - 1) on OpenMP's threads; each task writes only its own tiles.
template <typename Task>
void run_tasks(std::size_t count, Task&& task) {
  if (count <= 1) {
    if (count == 1) task(std::size_t{0});
    return;
  }
  const auto n = static_cast<long long>(count);
#pragma omp parallel for schedule(dynamic, 1)
  for (long long k = 0; k < n; ++k) task(static_cast<std::size_t>(k));
}

/// A column-major n x n matrix seen as tiles of kTile (the last row and column of tiles smaller).
struct Tiles {
  double* a;
  lapack_int n;
  lapack_int count() const { return (n + kTile - 1) / kTile; }
  lapack_int size(lapack_int i) const { return std::min(kTile, n - i * kTile); }
  double* at(lapack_int i, lapack_int j) const {
    return a + static_cast<std::ptrdiff_t>(j) * kTile * n + static_cast<std::ptrdiff_t>(i) * kTile;
  }
};

/// The pairs (i, j) with first <= j <= i < count: the lower tiles of a trailing matrix.
std::vector<std::pair<lapack_int, lapack_int>> lower_tiles(lapack_int first, lapack_int count) {
  std::vector<std::pair<lapack_int, lapack_int>> pairs;
  for (lapack_int j = first; j < count; ++j) {
    for (lapack_int i = j; i < count; ++i) pairs.emplace_back(i, j);
  }
  return pairs;
}

void copy_tile(const double* from, lapack_int ld_from, double* to, lapack_int ld_to, lapack_int rows,
               lapack_int cols) {
  for (lapack_int c = 0; c < cols; ++c) {
    std::copy_n(from + static_cast<std::ptrdiff_t>(c) * ld_from, rows, to + static_cast<std::ptrdiff_t>(c) * ld_to);
  }
}

/// In place, lower triangle: L -> W = L^-1 (dtrtri's blocked right-to-left sweep). Tile column
/// j of W, below its diagonal: W_ij = -(sum_{k=j+1..i} W_ik L_kj) W_jj, from the columns right
/// of it (already inverted) and the factor's column j, which is overwritten only when done.
void invert_lower_tiles(const Tiles& t) {
  const lapack_int count = t.count(), n = t.n;
  std::vector<double> panel(static_cast<std::size_t>(n) * kTile);
  for (lapack_int j = count - 1; j >= 0; --j) {
    const lapack_int bj = t.size(j), first = (j + 1) * kTile;
    double* p = panel.data();  // rows first..n-1 of the new column, leading dimension n
    run_tasks(static_cast<std::size_t>(count - j - 1), [&](std::size_t q) {
      const auto i = static_cast<lapack_int>(j + 1 + q);
      const lapack_int bi = t.size(i);
      double* pi = p + (i * kTile - first);
      copy_tile(t.at(i, j), n, pi, n, bi, bj);
      cblas_dtrmm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, bi, bj, 1.0, t.at(i, i), n, pi,
                  n);  // W_ii L_ij
      for (lapack_int k = j + 1; k < i; ++k) {
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, bi, bj, t.size(k), 1.0, t.at(i, k), n, t.at(k, j), n,
                    1.0, pi, n);
      }
    });
    LAPACKE_dtrtri_work(LAPACK_COL_MAJOR, 'L', 'N', bj, t.at(j, j), n);  // W_jj (L_jj is nonsingular)
    run_tasks(static_cast<std::size_t>(count - j - 1), [&](std::size_t q) {
      const auto i = static_cast<lapack_int>(j + 1 + q);
      double* pi = p + (i * kTile - first);
      cblas_dtrmm(CblasColMajor, CblasRight, CblasLower, CblasNoTrans, CblasNonUnit, t.size(i), bj, -1.0, t.at(j, j),
                  n, pi, n);
      copy_tile(pi, n, t.at(i, j), n, t.size(i), bj);
    });
  }
}

/// In place, lower triangle: W -> W^T W (dlauum's blocked sweep), tile row by tile row:
/// C_ij = sum_{k=i..} W_ki^T W_kj (j <= i) reads tile rows i and below only, so row i is
/// written once all of it is computed.
void lower_gram_tiles(const Tiles& t) {
  const lapack_int count = t.count(), n = t.n;
  std::vector<double> row(static_cast<std::size_t>(count) * kTile * kTile);  // tiles (i, 0..i), each kTile x kTile
  for (lapack_int i = 0; i < count; ++i) {
    const lapack_int bi = t.size(i);
    run_tasks(static_cast<std::size_t>(i + 1), [&](std::size_t q) {
      const auto j = static_cast<lapack_int>(q);
      const lapack_int bj = t.size(j);
      double* c = row.data() + static_cast<std::ptrdiff_t>(j) * kTile * kTile;  // bi x bj, leading dimension kTile
      copy_tile(t.at(i, j), n, c, kTile, bi, bj);
      if (j == i) {
        LAPACKE_dlauum_work(LAPACK_COL_MAJOR, 'L', bi, c, kTile);  // W_ii^T W_ii
        for (lapack_int k = i + 1; k < count; ++k) {
          cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, bi, t.size(k), 1.0, t.at(k, i), n, 1.0, c, kTile);
        }
      } else {
        cblas_dtrmm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, bi, bj, 1.0, t.at(i, i), n, c,
                    kTile);  // W_ii^T W_ij
        for (lapack_int k = i + 1; k < count; ++k) {
          cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, bi, bj, t.size(k), 1.0, t.at(k, i), n, t.at(k, j), n,
                      1.0, c, kTile);
        }
      }
    });
    for (lapack_int j = 0; j < i; ++j) {
      copy_tile(row.data() + static_cast<std::ptrdiff_t>(j) * kTile * kTile, kTile, t.at(i, j), n, bi, t.size(j));
    }
    const double* c = row.data() + static_cast<std::ptrdiff_t>(i) * kTile * kTile;
    double* d = t.at(i, i);
    for (lapack_int col = 0; col < bi; ++col) {  // the diagonal tile's lower triangle only
      std::copy(c + static_cast<std::ptrdiff_t>(col) * kTile + col, c + static_cast<std::ptrdiff_t>(col) * kTile + bi,
                d + static_cast<std::ptrdiff_t>(col) * n + col);
    }
  }
}

/// How many blocks of kTile columns (or rows) an extent makes, for operations whose columns (or
/// rows) are independent.
std::size_t blocks_of(Eigen::Index extent) { return static_cast<std::size_t>((extent + kTile - 1) / kTile); }

}  // namespace

bool cholesky(Eigen::MatrixXd& a) {
  const lapack_int n = checked_size(a.rows());
  if (n == 0) return true;
  blas_on_the_calling_thread();
  const Tiles t{a.data(), n};
  const lapack_int count = t.count();
  for (lapack_int k = 0; k < count; ++k) {
    const lapack_int bk = t.size(k);
    if (LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', bk, t.at(k, k), n) != 0) return false;
    run_tasks(static_cast<std::size_t>(count - k - 1), [&](std::size_t q) {  // L_ik = A_ik L_kk^-T
      const auto i = static_cast<lapack_int>(k + 1 + q);
      cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, t.size(i), bk, 1.0, t.at(k, k), n,
                  t.at(i, k), n);
    });
    const auto trailing = lower_tiles(k + 1, count);
    run_tasks(trailing.size(), [&](std::size_t q) {  // A_ij -= L_ik L_jk^T
      const auto [i, j] = trailing[q];
      if (i == j) {
        cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, t.size(i), bk, -1.0, t.at(i, k), n, 1.0, t.at(i, i), n);
      } else {
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, t.size(i), t.size(j), bk, -1.0, t.at(i, k), n, t.at(j, k),
                    n, 1.0, t.at(i, j), n);
      }
    });
  }
  a.triangularView<Eigen::StrictlyUpper>().setZero();
  return true;
}

Eigen::MatrixXd inverse_from_cholesky(const Eigen::MatrixXd& l) {
  Eigen::MatrixXd inv = l;
  invert_from_cholesky_lower(inv);
  inv.triangularView<Eigen::StrictlyUpper>() = inv.transpose();
  return inv;
}

void invert_from_cholesky_lower(Eigen::MatrixXd& l) {
  const lapack_int n = checked_size(l.rows());
  if (n == 0) return;
  if ((l.diagonal().array() == 0.0).any()) {
    throw std::runtime_error("Gaussian process: the covariance matrix could not be inverted");
  }
  blas_on_the_calling_thread();
  const Tiles t{l.data(), n};
  invert_lower_tiles(t);
  lower_gram_tiles(t);
}

void cholesky_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b) {
  const lapack_int n = checked_size(l.rows());
  if (n == 0 || b.cols() == 0) return;
  blas_on_the_calling_thread();
  run_tasks(blocks_of(b.cols()), [&](std::size_t q) {  // the columns are independent
    const Eigen::Index c0 = static_cast<Eigen::Index>(q) * kTile, cols = std::min<Eigen::Index>(kTile, b.cols() - c0);
    LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', n, checked_size(cols), l.data(), n, b.col(c0).data(), n);
  });
}

void lower_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b) {
  const auto n = checked_size(l.rows());
  if (n == 0 || b.cols() == 0) return;
  blas_on_the_calling_thread();
  run_tasks(blocks_of(b.cols()), [&](std::size_t q) {  // the columns are independent
    const Eigen::Index c0 = static_cast<Eigen::Index>(q) * kTile, cols = std::min<Eigen::Index>(kTile, b.cols() - c0);
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, n, checked_size(cols), 1.0, l.data(),
                n, b.col(c0).data(), checked_size(b.rows()));
  });
}

Eigen::MatrixXd gram(const Eigen::MatrixXd& a) {
  const auto n = checked_size(a.cols()), rows = checked_size(a.rows());
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
  if (n == 0 || rows == 0) return g;
  blas_on_the_calling_thread();
  const Tiles t{g.data(), n};
  const auto tiles = lower_tiles(0, t.count());
  run_tasks(tiles.size(), [&](std::size_t q) {  // G_ij = A_i^T A_j, the columns' tiles of A
    const auto [i, j] = tiles[q];
    const double* ai = a.col(static_cast<Eigen::Index>(i) * kTile).data();
    if (i == j) {
      cblas_dsyrk(CblasColMajor, CblasLower, CblasTrans, t.size(i), rows, 1.0, ai, rows, 0.0, t.at(i, i), n);
    } else {
      cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, t.size(i), t.size(j), rows, 1.0, ai, rows,
                  a.col(static_cast<Eigen::Index>(j) * kTile).data(), rows, 0.0, t.at(i, j), n);
    }
  });
  g.triangularView<Eigen::StrictlyUpper>() = g.transpose();
  return g;
}

Eigen::MatrixXd multiply(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.cols() != b.rows()) throw std::invalid_argument("multiply: inner dimensions differ");
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(a.rows(), b.cols());
  if (a.rows() == 0 || b.cols() == 0 || a.cols() == 0) return c;
  blas_on_the_calling_thread();
  run_tasks(blocks_of(a.rows()), [&](std::size_t q) {  // the rows of c are independent
    const Eigen::Index r0 = static_cast<Eigen::Index>(q) * kTile, rows = std::min<Eigen::Index>(kTile, a.rows() - r0);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, checked_size(rows), checked_size(b.cols()),
                checked_size(a.cols()), 1.0, a.data() + r0, checked_size(a.rows()), b.data(), checked_size(b.rows()),
                0.0, c.data() + r0, checked_size(c.rows()));
  });
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
