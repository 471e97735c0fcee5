// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include "kiseki/coop/triangulation.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

py::tuple result_tuple(const Triangulation& t) {
  return py::make_tuple(Eigen::VectorXd(t.position), Eigen::MatrixXd(t.covariance), Eigen::VectorXd(t.ranges),
                        t.intersection_angle);
}

std::vector<double> vector_of(const py::handle& obj, const char* name) {
  const DoubleArray a = as_doubles(obj, name);
  require_shape(a, name, 1);
  return std::vector<double>(a.data(), a.data() + a.size());
}

}  // namespace

void bind_coop(py::module_& m) {
  m.def(
      "triangulate_2d",
      [](const py::handle& standing, const py::handle& bearings, double bearing_sigma, double min_angle) {
        const DoubleArray s = as_doubles(standing, "standing_positions");
        require_shape(s, "standing_positions", 2, 2);
        std::vector<Eigen::Vector2d> points;
        for (py::ssize_t i = 0; i < s.shape(0); ++i) points.emplace_back(s.at(i, 0), s.at(i, 1));
        TriangulationParams p;
        p.bearing_sigma = bearing_sigma;
        p.min_intersection_angle = min_angle;
        return result_tuple(triangulate(points, vector_of(bearings, "bearings"), p));
      },
      "standing_positions"_a, "bearings"_a, "bearing_sigma"_a = 0.0, "min_intersection_angle"_a,
      "(position, covariance, ranges, intersection angle) from n x 2 positions and n bearings.");
  m.def(
      "triangulate_3d",
      [](const py::handle& standing, const py::handle& bearings, const py::handle& elevations, double bearing_sigma,
         double elevation_sigma, double min_angle) {
        const DoubleArray s = as_doubles(standing, "standing_positions");
        require_shape(s, "standing_positions", 2, 3);
        std::vector<Eigen::Vector3d> points;
        for (py::ssize_t i = 0; i < s.shape(0); ++i) points.emplace_back(s.at(i, 0), s.at(i, 1), s.at(i, 2));
        TriangulationParams p;
        p.bearing_sigma = bearing_sigma;
        p.elevation_sigma = elevation_sigma;
        p.min_intersection_angle = min_angle;
        return result_tuple(
            triangulate(points, vector_of(bearings, "bearings"), vector_of(elevations, "elevations"), p));
      },
      "standing_positions"_a, "bearings"_a, "elevations"_a, "bearing_sigma"_a = 0.0, "elevation_sigma"_a = 0.0,
      "min_intersection_angle"_a, "The same in 3-D, with n elevations.");
  m.attr("TRIANGULATION_MIN_ANGLE") = TriangulationParams{}.min_intersection_angle;
}

}  // namespace kiseki::bindings
