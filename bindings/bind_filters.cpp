// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/stl.h>

#include "kiseki/filters/particle_filter.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

void bind_filters(py::module_& m) {
  py::class_<ParticleFilter>(m, "ParticleFilter")
      .def(py::init([](int n, double a1, double a2, double a3, double a4, double threshold,
                       std::uint64_t seed) {
             ParticleFilterParams p;
             p.particles = n;
             p.alpha1 = a1, p.alpha2 = a2, p.alpha3 = a3, p.alpha4 = a4;
             p.resample_threshold = threshold;
             return ParticleFilter(p, seed);
           }),
           "particles"_a = 1000, "alpha1"_a = 0.05, "alpha2"_a = 0.01, "alpha3"_a = 0.05,
           "alpha4"_a = 0.01, "resample_threshold"_a = 0.5, "seed"_a = 0)
      .def("initialize", &ParticleFilter::initialize, "mean"_a, "sd_x"_a, "sd_y"_a, "sd_theta"_a)
      .def("set_particles",
           [](ParticleFilter& f, const py::handle& poses_in) {
             const auto p = as_doubles(poses_in, "poses");
             require_shape(p, "poses", 2, 3);
             std::vector<Pose2> particles(static_cast<std::size_t>(p.shape(0)));
             for (std::size_t i = 0; i < particles.size(); ++i) particles[i] = pose_from_row(p.data() + 3 * i);
             f.set_particles(particles);
           }, "poses"_a,
           "Replaces the particles by poses (n, 3), any n >= 1, with uniform weights.")
      .def("predict", &ParticleFilter::predict, "odom_before"_a, "odom_after"_a)
      .def("weight",
           [](ParticleFilter& f, const py::handle& lk_in) {
             const auto lk = as_doubles(lk_in, "likelihoods");
             require_shape(lk, "likelihoods", 1);
             return f.weight(std::vector<double>(lk.data(), lk.data() + lk.shape(0)));
           }, "likelihoods"_a)
      .def("resample_if_needed", &ParticleFilter::resample_if_needed)
      .def_property_readonly("effective_sample_size", &ParticleFilter::effective_sample_size)
      .def("estimate", &ParticleFilter::estimate)
      .def_property_readonly("poses",
                             [](const ParticleFilter& f) {
                               const auto& p = f.particles();
                               py::array_t<double> out({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
                               auto* d = out.mutable_data();
                               for (std::size_t i = 0; i < p.size(); ++i) {
                                 d[3 * i] = p[i].x, d[3 * i + 1] = p[i].y, d[3 * i + 2] = p[i].theta;
                               }
                               return out;
                             })
      .def_property_readonly("weights", [](const ParticleFilter& f) {
        return py::array_t<double>(static_cast<py::ssize_t>(f.weights().size()), f.weights().data());
      });
}

}  // namespace kiseki::bindings
