// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/stl.h>

#include "kiseki/mapping/log_odds_mapper.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

// Checked views of a batch of scans: poses (n, 3), ranges (n, b), angles (b,).
struct ScanBatch {
  DoubleArray poses;
  FloatArray ranges;
  DoubleArray angles;
  std::size_t n = 0, b = 0;
};

ScanBatch scan_batch(const py::handle& poses, const py::handle& ranges, const py::handle& angles) {
  ScanBatch s{as_doubles(poses, "poses"), as_floats(ranges, "ranges"), as_doubles(angles, "angles")};
  require_shape(s.poses, "poses", 2, 3);
  require_shape(s.angles, "angles", 1);
  require_shape(s.ranges, "ranges", 2, s.angles.shape(0));
  if (s.ranges.shape(0) != s.poses.shape(0)) {
    throw std::invalid_argument("ranges: expected one row per pose (" +
                                std::to_string(s.poses.shape(0)) + "), got " +
                                std::to_string(s.ranges.shape(0)));
  }
  require_finite(s.poses, "poses");
  require_finite(s.angles, "angles");
  s.n = static_cast<std::size_t>(s.poses.shape(0));
  s.b = static_cast<std::size_t>(s.angles.shape(0));
  return s;
}

}  // namespace

void bind_mapping(py::module_& m) {
  py::class_<LogOddsParams>(m, "LogOddsParams")
      .def(py::init<>())
      .def_readwrite("resolution", &LogOddsParams::resolution)
      .def_readwrite("max_range", &LogOddsParams::max_range)
      .def_readwrite("usable_range", &LogOddsParams::usable_range)
      .def_readwrite("min_range", &LogOddsParams::min_range)
      .def_readwrite("clear_on_no_return", &LogOddsParams::clear_on_no_return)
      .def_readwrite("prob_hit", &LogOddsParams::prob_hit)
      .def_readwrite("prob_miss", &LogOddsParams::prob_miss)
      .def_readwrite("clamp_min", &LogOddsParams::clamp_min)
      .def_readwrite("clamp_max", &LogOddsParams::clamp_max)
      .def_readwrite("occupied_thresh", &LogOddsParams::occupied_thresh)
      .def_readwrite("free_thresh", &LogOddsParams::free_thresh)
      .def("validate", [](const LogOddsParams& p) { validate(p); });

  py::class_<LogOddsMapper>(m, "LogOddsMapper")
      .def(py::init<double, double, double, double, const LogOddsParams&>(), "min_x"_a, "min_y"_a,
           "max_x"_a, "max_y"_a, "params"_a)
      .def(
          "integrate_scans",
          [](LogOddsMapper& mapper, const py::handle& poses, const py::handle& ranges,
             const py::handle& angles) {
            const ScanBatch s = scan_batch(poses, ranges, angles);
            py::gil_scoped_release release;
            for (std::size_t i = 0; i < s.n; ++i) {
              mapper.integrate_scan(pose_from_row(s.poses.data() + 3 * i),
                                    s.ranges.data() + i * s.b, s.angles.data(), s.b);
            }
          },
          "poses"_a, "ranges"_a, "angles"_a,
          "Adds scans (ranges (n, b)) taken at sensor poses (n, 3); releases the GIL.")
      .def("to_occupancy", &LogOddsMapper::to_occupancy)
      .def_property_readonly("scans_integrated", &LogOddsMapper::scans_integrated)
      .def_static(
          "scan_bounds",
          [](const py::handle& poses, const py::handle& ranges, const py::handle& angles,
             const LogOddsParams& p) {
            const ScanBatch s = scan_batch(poses, ranges, angles);
            return LogOddsMapper::scan_bounds(s.poses.data(), s.ranges.data(), s.angles.data(),
                                              s.n, s.b, p);
          },
          "poses"_a, "ranges"_a, "angles"_a, "params"_a);

  m.def(
      "endpoint_agreement",
      [](const OccupancyGrid& grid, const py::handle& poses, const py::handle& ranges,
         const py::handle& angles, double max_range, int neighbourhood, int occupied_threshold) {
        const ScanBatch s = scan_batch(poses, ranges, angles);
        if (occupied_threshold < 0 || occupied_threshold > 127) {
          throw std::invalid_argument("occupied_threshold must be in 0..127");
        }
        py::gil_scoped_release release;
        return endpoint_agreement(grid, s.poses.data(), s.ranges.data(), s.angles.data(), s.n, s.b,
                                  max_range, neighbourhood,
                                  static_cast<std::int8_t>(occupied_threshold));
      },
      "grid"_a, "poses"_a, "ranges"_a, "angles"_a, "max_range"_a, "neighbourhood"_a = 1,
      "occupied_threshold"_a = 65,
      "(hits, endpoints): scan endpoints landing on or next to occupied cells.");
}

}  // namespace kiseki::bindings
