// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <memory>
#include <string>

#include "kiseki/gp/hilbert_gp.hpp"
#include "kiseki/gp/hyperparameters.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

/// A (n, d) float64 array kept alive while C++ reads it through an Eigen map (no copy).
struct Rows {
  DoubleArray array;
  Rows(const py::handle& obj, const char* name) : array(as_doubles(obj, name)) { require_shape(array, name, 2); }
  Eigen::Map<const RowMatrix> map() const { return {array.data(), array.shape(0), array.shape(1)}; }
};

SquaredExponential kernel_of(double sigma_f, double length_scale, double sigma_n) {
  SquaredExponential k{sigma_f, length_scale, sigma_n};
  k.validate();
  return k;
}

py::tuple prediction(const RowMatrix& mean, const Eigen::VectorXd& variance) {
  py::array_t<double> m({mean.rows(), mean.cols()});
  std::copy(mean.data(), mean.data() + mean.size(), m.mutable_data());
  py::array_t<double> v(variance.size());
  std::copy(variance.data(), variance.data() + variance.size(), v.mutable_data());
  return py::make_tuple(m, v);
}

}  // namespace

void bind_gp(py::module_& m) {
  py::class_<ExactGaussianProcess>(m, "ExactGaussianProcess",
                                   "Exact GP regression with a squared-exponential kernel (see kiseki.gp.ExactGP).")
      .def(py::init([](const py::handle& inputs, const py::handle& targets, double sigma_f, double length_scale,
                       double sigma_n, bool constant_mean, bool truncated_prediction) {
             const Rows x(inputs, "inputs");
             const Rows y(targets, "targets");
             const SquaredExponential k = kernel_of(sigma_f, length_scale, sigma_n);
             py::gil_scoped_release release;
             return std::make_unique<ExactGaussianProcess>(
                 x.map(), y.map(), k, constant_mean ? GpMean::constant : GpMean::zero, truncated_prediction);
           }),
           "inputs"_a, "targets"_a, "sigma_f"_a, "length_scale"_a, "sigma_n"_a, "constant_mean"_a = true,
           "truncated_prediction"_a = true)
      .def(
          "predict",
          [](const ExactGaussianProcess& gp, const py::handle& points, double truncation) {
            const Rows p(points, "points");
            RowMatrix mean;
            Eigen::VectorXd variance;
            {
              py::gil_scoped_release release;
              gp.predict(p.map(), mean, &variance, truncation);
            }
            return prediction(mean, variance);
          },
          "points"_a, "truncation"_a = 1e-13, "(mean (m, k), variance (m,)) of the noise-free field.")
      .def_property_readonly("log_marginal_likelihood", &ExactGaussianProcess::log_marginal_likelihood)
      .def_property_readonly("size", &ExactGaussianProcess::size)
      .def_property_readonly("dimension", &ExactGaussianProcess::dimension)
      .def_property_readonly("outputs", &ExactGaussianProcess::outputs)
      .def_property_readonly("jitter", &ExactGaussianProcess::jitter)
      .def_property_readonly("prior_mean", [](const ExactGaussianProcess& gp) { return Eigen::VectorXd(gp.prior_mean()); });

  py::class_<HilbertGaussianProcess>(m, "HilbertGaussianProcess",
                                     "Reduced-rank (Hilbert-space) GP regression (see kiseki.gp.HilbertGP).")
      .def(py::init([](const py::handle& inputs, const py::handle& targets, double sigma_f, double length_scale,
                       double sigma_n, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, double tolerance,
                       Eigen::Index max_basis, bool constant_mean) {
             const Rows x(inputs, "inputs");
             const Rows y(targets, "targets");
             const SquaredExponential k = kernel_of(sigma_f, length_scale, sigma_n);
             py::gil_scoped_release release;
             return std::make_unique<HilbertGaussianProcess>(x.map(), y.map(), k, lower, upper, tolerance, max_basis,
                                                             constant_mean ? GpMean::constant : GpMean::zero);
           }),
           "inputs"_a, "targets"_a, "sigma_f"_a, "length_scale"_a, "sigma_n"_a, "lower"_a, "upper"_a,
           "tolerance"_a = 1e-4, "max_basis"_a = 20000, "constant_mean"_a = true)
      .def(
          "predict",
          [](const HilbertGaussianProcess& gp, const py::handle& points) {
            const Rows p(points, "points");
            RowMatrix mean;
            Eigen::VectorXd variance;
            {
              py::gil_scoped_release release;
              gp.predict(p.map(), mean, &variance);
            }
            return prediction(mean, variance);
          },
          "points"_a, "(mean (m, k), variance (m,)) of the noise-free field.")
      .def_property_readonly("basis_size", &HilbertGaussianProcess::basis_size)
      .def_property_readonly("size", &HilbertGaussianProcess::size)
      .def_property_readonly("dimension", &HilbertGaussianProcess::dimension)
      .def_property_readonly("outputs", &HilbertGaussianProcess::outputs)
      .def_property_readonly("prior_mean",
                             [](const HilbertGaussianProcess& gp) { return Eigen::VectorXd(gp.prior_mean()); });

  m.def(
      "gp_log_marginal_likelihood",
      [](const py::handle& inputs, const py::handle& targets, double sigma_f, double length_scale, double sigma_n) {
        const Rows x(inputs, "inputs");
        const Rows y(targets, "targets");
        check_training_data(x.map(), y.map());
        const SquaredExponential k = kernel_of(sigma_f, length_scale, sigma_n);
        LogMarginalLikelihood r;
        {
          py::gil_scoped_release release;
          r = log_marginal_likelihood(x.map(), y.map(), k);
        }
        return py::make_tuple(r.value, Eigen::Vector3d(r.gradient));
      },
      "inputs"_a, "targets"_a, "sigma_f"_a, "length_scale"_a, "sigma_n"_a,
      "(log p(Y | X), its gradient in (log sigma_f, log l, log sigma_n)); targets used as given.");
  m.def(
      "gp_initial_kernel",
      [](const py::handle& inputs, const py::handle& targets) {
        const Rows x(inputs, "inputs");
        const Rows y(targets, "targets");
        const SquaredExponential k = initial_kernel(x.map(), y.map());
        return py::make_tuple(k.sigma_f, k.length_scale, k.sigma_n);
      },
      "inputs"_a, "targets"_a);
  m.def(
      "gp_fit_hyperparameters",
      [](const py::handle& inputs, const py::handle& targets, double sigma_f, double length_scale, double sigma_n,
         int restarts, std::uint64_t seed, int max_iterations, double tolerance, bool scan, bool stop_at_repeat) {
        const Rows x(inputs, "inputs");
        const Rows y(targets, "targets");
        const SquaredExponential initial = kernel_of(sigma_f, length_scale, sigma_n);
        HyperparameterOptions o;
        o.restarts = restarts;
        o.seed = seed;
        o.max_iterations = max_iterations;
        o.tolerance = tolerance;
        o.scan = scan;
        o.stop_at_repeat = stop_at_repeat;
        HyperparameterFit fit;
        {
          py::gil_scoped_release release;
          fit = fit_hyperparameters(x.map(), y.map(), initial, o);
        }
        py::list optima;
        for (const auto& [k, lml] : fit.optima) optima.append(py::make_tuple(k.sigma_f, k.length_scale, k.sigma_n, lml));
        return py::make_tuple(fit.kernel.sigma_f, fit.kernel.length_scale, fit.kernel.sigma_n,
                              fit.log_marginal_likelihood, fit.evaluations, fit.gradients, fit.start_values, optima);
      },
      "inputs"_a, "targets"_a, "sigma_f"_a, "length_scale"_a, "sigma_n"_a, "restarts"_a = 3, "seed"_a = 0,
      "max_iterations"_a = 100, "tolerance"_a = 1e-6, "scan"_a = true, "stop_at_repeat"_a = true,
      "(sigma_f, l, sigma_n, LML, likelihood values, gradients, best LML per start made, the distinct optima as "
      "(sigma_f, l, sigma_n, LML)); targets used as given.");
}

}  // namespace kiseki::bindings
