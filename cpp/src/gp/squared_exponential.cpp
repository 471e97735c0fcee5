// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/gp/squared_exponential.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kiseki {

void SquaredExponential::validate() const {
  const auto check = [](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) {
      throw std::invalid_argument(std::string("squared-exponential kernel: ") + name +
                                  " must be a finite number > 0, got " + std::to_string(v));
    }
  };
  check(sigma_f, "sigma_f");
  check(length_scale, "length_scale");
  check(sigma_n, "sigma_n");
}

double SquaredExponential::operator()(double squared_distance) const {
  return sigma_f * sigma_f * std::exp(-0.5 * squared_distance / (length_scale * length_scale));
}

double SquaredExponential::cutoff_radius(double relative) const {
  if (!(relative > 0.0 && relative < 1.0)) throw std::invalid_argument("cutoff_radius: relative must be in (0, 1)");
  return length_scale * std::sqrt(-2.0 * std::log(relative));
}

Eigen::MatrixXd squared_distances(const Eigen::Ref<const RowMatrix>& a, const Eigen::Ref<const RowMatrix>& b) {
  if (a.cols() != b.cols()) throw std::invalid_argument("squared_distances: points of different dimensions");
  Eigen::MatrixXd d(a.rows(), b.rows());
  const Eigen::Index dims = a.cols();
#pragma omp parallel for schedule(static) if (a.rows() * b.rows() > 250000)
  for (Eigen::Index j = 0; j < b.rows(); ++j) {
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
      double s = 0.0;
      for (Eigen::Index k = 0; k < dims; ++k) {
        const double t = a(i, k) - b(j, k);
        s += t * t;
      }
      d(i, j) = s;
    }
  }
  return d;
}

Eigen::MatrixXd kernel_matrix(const SquaredExponential& kernel, const Eigen::Ref<const RowMatrix>& a,
                              const Eigen::Ref<const RowMatrix>& b) {
  Eigen::MatrixXd k = squared_distances(a, b);
  const double f2 = kernel.sigma_f * kernel.sigma_f;
  const double c = -0.5 / (kernel.length_scale * kernel.length_scale);
  // Values below e^-700 become 0: subnormal numbers would slow every product with the matrix by
  // two orders of magnitude (the CPU's microcode assists) and carry no information.
  k = (k.array() * c < -700.0).select(0.0, (k.array() * c).exp() * f2);
  return k;
}

}  // namespace kiseki
