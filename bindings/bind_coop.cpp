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
  m.def(
      "triangulate_pairs",
      [](const py::handle& a, const py::handle& b, const py::handle& bearing_a, const py::handle& bearing_b,
         double min_angle) {
        const DoubleArray pa = as_doubles(a, "a"), pb = as_doubles(b, "b");
        require_shape(pa, "a", 2, 2);
        require_shape(pb, "b", 2, 2);
        std::vector<Eigen::Vector2d> va, vb;
        for (py::ssize_t i = 0; i < pa.shape(0); ++i) va.emplace_back(pa.at(i, 0), pa.at(i, 1));
        for (py::ssize_t i = 0; i < pb.shape(0); ++i) vb.emplace_back(pb.at(i, 0), pb.at(i, 1));
        const std::vector<double> ba = vector_of(bearing_a, "bearing_a"), bb = vector_of(bearing_b, "bearing_b");
        TriangulationParams p;
        p.min_intersection_angle = min_angle;
        std::vector<Eigen::Vector2d> out;
        {
          py::gil_scoped_release release;
          out = triangulate_pairs(va, vb, ba, bb, p);
        }
        py::array_t<double> result({static_cast<py::ssize_t>(out.size()), py::ssize_t{2}});
        auto r = result.mutable_unchecked<2>();
        for (std::size_t k = 0; k < out.size(); ++k) r(k, 0) = out[k].x(), r(k, 1) = out[k].y();
        return result;
      },
      "a"_a, "b"_a, "bearing_a"_a, "bearing_b"_a, "min_intersection_angle"_a,
      "(m, 2) intersections of the lines of sight from a[k] and b[k] (m x 2 each).");
  m.attr("TRIANGULATION_MIN_ANGLE") = TriangulationParams{}.min_intersection_angle;
}

}  // namespace kiseki::bindings
