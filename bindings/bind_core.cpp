// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/pose.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/core/threads.hpp"
#include "kiseki/core/versions.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

void check_finite_pose(double x, double y, double theta) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(theta)) {
    throw std::invalid_argument("Pose2: x, y and theta must be finite");
  }
}

void bind_poses(py::module_& m) {
  py::class_<Pose2>(m, "Pose2", "A planar pose (x, y in metres, theta in radians, wrapped).")
      .def(py::init([](double x, double y, double theta) {
             check_finite_pose(x, y, theta);
             return Pose2(x, y, theta);
           }),
           "x"_a = 0.0, "y"_a = 0.0, "theta"_a = 0.0)
      .def_readonly("x", &Pose2::x)
      .def_readonly("y", &Pose2::y)
      .def_readonly("theta", &Pose2::theta)
      .def("compose", &Pose2::compose, "other"_a)
      .def("__mul__", &Pose2::compose)
      .def("inverse", &Pose2::inverse)
      .def("between", &Pose2::between, "other"_a)
      .def("transform_point", &Pose2::transform_point, "point"_a)
      .def("to_array", [](const Pose2& p) { return p.vector(); })
      .def("__repr__", [](const Pose2& p) {
        return "Pose2(x=" + std::to_string(p.x) + ", y=" + std::to_string(p.y) +
               ", theta=" + std::to_string(p.theta) + ")";
      })
      .def(py::pickle([](const Pose2& p) { return py::make_tuple(p.x, p.y, p.theta); },
                      [](const py::tuple& t) {
                        return Pose2(t[0].cast<double>(), t[1].cast<double>(), t[2].cast<double>());
                      }));

  py::class_<Pose3>(m, "Pose3", "A rigid 3-D pose: translation and unit quaternion.")
      .def(py::init([](const Eigen::Vector3d& t, const Eigen::Vector4d& wxyz) {
             if (!t.allFinite() || !wxyz.allFinite()) {
               throw std::invalid_argument("Pose3: translation and quaternion must be finite");
             }
             return Pose3(t, Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]));
           }),
           "translation"_a, "quaternion_wxyz"_a)
      .def_static("from_rpy", &Pose3::from_rpy, "x"_a, "y"_a, "z"_a, "roll"_a, "pitch"_a, "yaw"_a)
      .def_property_readonly("translation", [](const Pose3& p) { return p.translation; })
      .def_property_readonly("quaternion_wxyz",
                             [](const Pose3& p) {
                               const auto& q = p.rotation;
                               return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
                             })
      .def("matrix", [](const Pose3& p) { return Eigen::Matrix4d(p.isometry().matrix()); })
      .def("compose", &Pose3::compose, "other"_a)
      .def("__mul__", &Pose3::compose)
      .def("inverse", &Pose3::inverse)
      .def("transform_point", &Pose3::transform_point, "point"_a)
      .def("yaw", &Pose3::yaw)
      .def("to_pose2", &Pose3::to_pose2);
}

void bind_random(py::module_& m) {
  m.def("derive_seed", &derive_seed, "seed"_a, "stream"_a,
        "A new 64-bit seed for sub-stream number stream of seed (SplitMix64).");
  py::class_<Random>(m, "Random", "kiseki's seeded generator (mt19937_64, portable distributions).")
      .def(py::init<std::uint64_t>(), "seed"_a)
      .def_property_readonly("seed", &Random::seed)
      .def("uniform",
           [](Random& r, double low, double high, py::ssize_t size) {
             if (size < 0) throw std::invalid_argument("size must be >= 0");
             // NaN or infinite bounds gave NaN or infinite draws; so did bounds whose span
             // overflows (-1e308 .. 1e308)
             if (!std::isfinite(high - low)) {
               throw std::invalid_argument("uniform: low and high must be finite numbers less than 1e308 apart");
             }
             py::array_t<double> out(size);
             auto* p = out.mutable_data();
             for (py::ssize_t i = 0; i < size; ++i) p[i] = r.uniform(low, high);
             return out;
           },
           "low"_a = 0.0, "high"_a = 1.0, "size"_a = 1)
      .def("normal",
           [](Random& r, double mean, double stddev, py::ssize_t size) {
             if (size < 0) throw std::invalid_argument("size must be >= 0");
             if (!(stddev >= 0.0)) throw std::invalid_argument("stddev must be >= 0");
             if (!std::isfinite(mean) || !std::isfinite(stddev)) {  // NaN or infinite draws
               throw std::invalid_argument("normal: mean and stddev must be finite");
             }
             py::array_t<double> out(size);
             auto* p = out.mutable_data();
             for (py::ssize_t i = 0; i < size; ++i) p[i] = r.normal(mean, stddev);
             return out;
           },
           "mean"_a = 0.0, "stddev"_a = 1.0, "size"_a = 1)
      .def("below", &Random::below, "n"_a)
      .def("split", &Random::split, "stream"_a);
}

}  // namespace

void bind_core(py::module_& m) {
  m.def("normalize_angle", py::vectorize(&normalize_angle), "angle"_a,
        "Wraps angles (scalar or array) to [-pi, pi).");
  m.def("library_versions", &library_versions);
  m.attr("MAX_THREADS") = kMaxThreads;  // the most threads any call may ask for
  bind_poses(m);
  bind_random(m);
}

}  // namespace kiseki::bindings
