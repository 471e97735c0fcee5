// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <cmath>
#include <string>

#include "kiseki/speed/speed_reference.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

Pose2 pose_of(const py::handle& obj) {
  if (py::isinstance<Pose2>(obj)) return obj.cast<Pose2>();
  const DoubleArray a = as_doubles(obj, "pose");
  if (a.ndim() != 1 || a.size() != 3) {
    throw std::invalid_argument("pose: expected a Pose2 or (x, y, theta), got shape " + shape_string(a));
  }
  require_finite(a, "pose");
  return {a.data()[0], a.data()[1], a.data()[2]};
}

/// Holds the numpy arrays a PlanarScan points into.
struct ScanArrays {
  DoubleArray angles;
  FloatArray ranges;
  PlanarScan scan;
  ScanArrays(const py::handle& a, const py::handle& r, double max_range)
      : angles(as_doubles(a, "angles")), ranges(as_floats(r, "ranges")) {
    require_shape(angles, "angles", 1);
    require_shape(ranges, "ranges", 1);
    if (angles.size() != ranges.size()) {
      throw std::invalid_argument("angles and ranges differ in length: " + std::to_string(angles.size()) + " vs " +
                                  std::to_string(ranges.size()));
    }
    scan = {angles.data(), ranges.data(), static_cast<std::size_t>(angles.size()), max_range};
  }
};

}  // namespace

void bind_speed(py::module_& m) {
  m.def(
      "occlusion_ratio",
      [](const OccupancyGrid& grid, const py::handle& pose, const py::handle& angles, const py::handle& ranges,
         double max_range, double half_angle, py::object heading, int free_threshold,
         bool with_labels) -> py::tuple {
        const Pose2 sensor = pose_of(pose);
        const ScanArrays s(angles, ranges, max_range);
        if (free_threshold < 0 || free_threshold > 100) throw std::invalid_argument("free_threshold must be in 0..100");
        OcclusionRatioOptions options;
        options.half_angle = half_angle;
        options.free_threshold = static_cast<std::int8_t>(free_threshold);
        const double h = heading.is_none() ? sensor.theta : heading.cast<double>();
        OcclusionRatio r;
        cv::Mat labels;
        {
          py::gil_scoped_release release;
          r = occlusion_ratio(grid, sensor, s.scan, h, options, with_labels ? &labels : nullptr);
        }
        if (!with_labels) return py::make_tuple(r.ratio, r.seen_cells, r.free_cells);
        return py::make_tuple(r.ratio, r.seen_cells, r.free_cells, mat_to_numpy(labels));
      },
      "grid"_a, "pose"_a, "angles"_a, "ranges"_a, "max_range"_a, "half_angle"_a, "heading"_a = py::none(),
      "free_threshold"_a = 25, "with_labels"_a = false,
      "(ratio, seen cells, free cells[, labels]) of eq. 1 (see kiseki.speed.occlusion_ratio); labels: "
      "uint8 [y, x], 0 outside the region, 1 occluded free cell, 2 seen.");
  m.def(
      "passage_width",
      [](const py::handle& angles, const py::handle& ranges, double max_range, double heading, double half_band) {
        const ScanArrays s(angles, ranges, max_range);
        const PassageWidth w = passage_width(s.scan, heading, half_band);
        return py::make_tuple(w.width, w.left, w.right);
      },
      "angles"_a, "ranges"_a, "max_range"_a, "heading"_a = 0.0, "half_band"_a = 0.05,
      "(w, left, right): eq. 2's w, measured on the line across the heading (sensor frame, rad).");
  m.def("width_factor", &width_factor, "w"_a, "w1"_a, "w2"_a, "a"_a, "f(w) of eq. 3 (the sigmoid, typo corrected).");
  m.def(
      "speed_reference",
      [](const OccupancyGrid& grid, const py::handle& pose, const py::handle& angles, const py::handle& ranges,
         double max_range, py::object heading, double v_max, double half_angle, int free_threshold, double w1,
         double w2, double a, double half_band, bool use_occlusion, bool use_width) {
        const Pose2 sensor = pose_of(pose);
        const ScanArrays s(angles, ranges, max_range);
        if (free_threshold < 0 || free_threshold > 100) throw std::invalid_argument("free_threshold must be in 0..100");
        SpeedReferenceParams p;
        p.v_max = v_max;
        p.occlusion.half_angle = half_angle;
        p.occlusion.free_threshold = static_cast<std::int8_t>(free_threshold);
        p.w1 = w1, p.w2 = w2, p.a = a, p.half_band = half_band;
        p.use_occlusion = use_occlusion, p.use_width = use_width;
        const double h = heading.is_none() ? sensor.theta : heading.cast<double>();
        SpeedReference r;
        {
          py::gil_scoped_release release;
          r = speed_reference(grid, sensor, s.scan, h, p);
        }
        py::dict out;
        out["v_ref"] = r.v_ref;
        out["ratio"] = r.occlusion.ratio;
        out["seen_cells"] = r.occlusion.seen_cells;
        out["free_cells"] = r.occlusion.free_cells;
        out["width"] = r.passage.width;
        out["width_left"] = r.passage.left;
        out["width_right"] = r.passage.right;
        out["width_factor"] = r.width_factor;
        return out;
      },
      "grid"_a, "pose"_a, "angles"_a, "ranges"_a, "max_range"_a, "heading"_a = py::none(), "v_max"_a = 0.5,
      "half_angle"_a = M_PI / 2, "free_threshold"_a = 25, "w1"_a = 0.70, "w2"_a = 2.0, "a"_a = 4.9,
      "half_band"_a = 0.05, "use_occlusion"_a = true, "use_width"_a = true,
      "Eq. 4's speed reference and its factors, as a dict.");
}

}  // namespace kiseki::bindings
