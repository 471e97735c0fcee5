// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>

#include "kiseki/grid/distance_field.hpp"
#include "kiseki/grid/local_window.hpp"
#include "kiseki/grid/map_image.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

using Int8Array = py::array_t<std::int8_t, py::array::c_style>;

OccupancyGrid grid_from_cells(const py::array& cells, double resolution, const Pose2& origin) {
  if (cells.dtype().kind() != 'i' || cells.itemsize() != 1) {
    throw std::invalid_argument("cells: expected dtype int8 (0 free, 100 occupied, -1 unknown), got " +
                                std::string(py::str(cells.dtype())));
  }
  require_shape(cells, "cells", 2);
  if (cells.shape(0) == 0 || cells.shape(1) == 0) throw std::invalid_argument("cells: empty array");
  const auto c = Int8Array::ensure(cells);
  const std::int8_t* v = c.data();
  for (py::ssize_t i = 0; i < c.size(); ++i) {
    if (v[i] < kUnknown || v[i] > kOccupied) {
      throw std::invalid_argument(
          "cells: values must lie in -1..100 (-1 unknown, 0 free, 100 occupied), got " +
          std::to_string(static_cast<int>(v[i])) + " at row " + std::to_string(i / c.shape(1)) +
          ", column " + std::to_string(i % c.shape(1)));
    }
  }
  OccupancyGrid grid(static_cast<int>(c.shape(1)), static_cast<int>(c.shape(0)), resolution, origin);
  std::memcpy(grid.cells().data, c.data(), static_cast<std::size_t>(c.size()));
  return grid;
}

// A writable numpy view of a cv::Mat owned by `owner` (kept alive by the array's base).
template <typename T>
py::array mat_view(cv::Mat& mat, py::handle owner) {
  return py::array_t<T>({mat.rows, mat.cols}, {static_cast<py::ssize_t>(mat.step[0]),
                                               static_cast<py::ssize_t>(sizeof(T))},
                        mat.ptr<T>(0), owner);
}

cv::Mat numpy_to_image(const py::array& image) {
  const auto kind = image.dtype().kind();
  const auto size = image.itemsize();
  if (kind != 'u' || (size != 1 && size != 2)) {
    throw std::invalid_argument("image: expected dtype uint8 or uint16, got " +
                                std::string(py::str(image.dtype())));
  }
  if (image.ndim() != 2 && !(image.ndim() == 3 && image.shape(2) >= 1 && image.shape(2) <= 4)) {
    throw std::invalid_argument("image: expected shape (h, w) or (h, w, 1..4), got " +
                                shape_string(image));
  }
  const int channels = image.ndim() == 3 ? static_cast<int>(image.shape(2)) : 1;
  const auto c = py::array::ensure(image, py::array::c_style);
  cv::Mat view(static_cast<int>(c.shape(0)), static_cast<int>(c.shape(1)),
               CV_MAKETYPE(size == 1 ? CV_8U : CV_16U, channels), const_cast<void*>(c.data()));
  return view.clone();
}

MapImageParams make_params(const std::string& mode, bool negate, double occ, double free) {
  MapImageParams p;
  if (mode == "trinary") p.mode = MapMode::Trinary;
  else if (mode == "scale") p.mode = MapMode::Scale;
  else if (mode == "raw") p.mode = MapMode::Raw;
  else throw std::invalid_argument("mode must be 'trinary', 'scale' or 'raw', got '" + mode + "'");
  p.negate = negate;
  p.occupied_thresh = occ;
  p.free_thresh = free;
  return p;
}

RayCastOptions make_options(double max_range, int occupied_threshold, bool unknown_is_obstacle) {
  if (occupied_threshold < 0 || occupied_threshold > 127) {
    throw std::invalid_argument("occupied_threshold must be in 0..127");
  }
  RayCastOptions o;
  o.max_range = max_range;
  o.occupied_threshold = static_cast<std::int8_t>(occupied_threshold);
  o.unknown_is_obstacle = unknown_is_obstacle;
  return o;
}

py::array_t<double> cast_scans(const OccupancyGrid& g, const py::handle& poses_in,
                               const py::handle& angles_in, const RayCastOptions& o) {
  const auto poses = as_doubles(poses_in, "poses");
  const auto angles = as_doubles(angles_in, "angles");
  require_shape(poses, "poses", 2, 3);
  require_shape(angles, "angles", 1);
  require_finite(poses, "poses");
  require_finite(angles, "angles");
  const auto n = poses.shape(0), b = angles.shape(0);
  py::array_t<double> out({n, b});
  double* dst = out.mutable_data();
  const double* p = poses.data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      cast_scan(g, pose_from_row(p + 3 * i), angles.data(), static_cast<std::size_t>(b), o,
                dst + i * b);
    }
  }
  return out;
}

void bind_ray_casting(py::class_<OccupancyGrid>& cls) {
  const auto opts = [](double m, int t, bool u) { return make_options(m, t, u); };
  cls.def(
         "cast_ray",
         [opts](const OccupancyGrid& g, double x, double y, double heading, double max_range,
                int occupied_threshold, bool unknown_is_obstacle) {
           const RayHit h =
               cast_ray(g, {x, y}, heading, opts(max_range, occupied_threshold, unknown_is_obstacle));
           return py::make_tuple(h.range, h.hit, py::make_tuple(h.cell.x, h.cell.y));
         },
         "x"_a, "y"_a, "heading"_a, "max_range"_a = 30.0, "occupied_threshold"_a = 65,
         "unknown_is_obstacle"_a = false,
         "Casts one ray; returns (range, hit, (cx, cy) of the obstacle cell).")
      .def(
          "cells_on_ray",
          [opts](const OccupancyGrid& g, double x, double y, double heading, double max_range,
                 int occupied_threshold, bool unknown_is_obstacle) {
            const auto cells = cells_on_ray(g, {x, y}, heading,
                                            opts(max_range, occupied_threshold, unknown_is_obstacle));
            py::array_t<int> out({static_cast<py::ssize_t>(cells.size()), py::ssize_t{2}});
            auto* p = out.mutable_data();
            for (std::size_t i = 0; i < cells.size(); ++i) p[2 * i] = cells[i].x, p[2 * i + 1] = cells[i].y;
            return out;
          },
          "x"_a, "y"_a, "heading"_a, "max_range"_a = 30.0, "occupied_threshold"_a = 65,
          "unknown_is_obstacle"_a = false, "The (cx, cy) cells a ray crosses, in order.")
      .def(
          "cast_scans",
          [opts](const OccupancyGrid& g, const py::handle& poses, const py::handle& angles,
                 double max_range, int occupied_threshold, bool unknown_is_obstacle) {
            return cast_scans(g, poses, angles, opts(max_range, occupied_threshold, unknown_is_obstacle));
          },
          "poses"_a, "angles"_a, "max_range"_a = 30.0, "occupied_threshold"_a = 65,
          "unknown_is_obstacle"_a = false,
          "Ranges (n, b) of b beams cast from each of n sensor poses (n, 3); releases the GIL.");
}

void bind_occupancy_grid(py::module_& m) {
  py::class_<OccupancyGrid> cls(m, "OccupancyGrid");
  cls.def(py::init<int, int, double, const Pose2&, std::int8_t>(), "width"_a, "height"_a,
          "resolution"_a, "origin"_a = Pose2(), "fill"_a = kUnknown)
      .def(py::init(&grid_from_cells), "cells"_a, "resolution"_a, "origin"_a = Pose2(),
           "A grid holding a copy of int8 cells (row = y).")
      .def_property_readonly("width", &OccupancyGrid::width)
      .def_property_readonly("height", &OccupancyGrid::height)
      .def_property_readonly("resolution", &OccupancyGrid::resolution)
      .def_property("origin", &OccupancyGrid::origin, &OccupancyGrid::set_origin)
      .def_property_readonly(
          "cells", [](py::object self) {
            return mat_view<std::int8_t>(self.cast<OccupancyGrid&>().cells(), self);
          },
          "Writable int8 view (height, width) of the cells, no copy.")
      .def("world_to_cell",
           [](const OccupancyGrid& g, const py::handle& pts) {
             const auto a = as_doubles(pts, "points");
             require_shape(a, "points", 2, 2);
             require_finite(a, "points");
             py::array_t<int> out({a.shape(0), py::ssize_t{2}});
             auto* o = out.mutable_data();
             for (py::ssize_t i = 0; i < a.shape(0); ++i) {
               const CellIndex c = g.world_to_cell({a.data()[2 * i], a.data()[2 * i + 1]});
               o[2 * i] = c.x, o[2 * i + 1] = c.y;
             }
             return out;
           }, "points"_a, "Cells (n, 2) containing world points (n, 2); may lie outside.")
      .def("cell_to_world",
           [](const OccupancyGrid& g, const py::handle& cells) {
             const auto a = as_doubles(cells, "cells");
             require_shape(a, "cells", 2, 2);
             py::array_t<double> out({a.shape(0), py::ssize_t{2}});
             auto* o = out.mutable_data();
             for (py::ssize_t i = 0; i < a.shape(0); ++i) {
               const Eigen::Vector2d w = g.grid_to_world({a.data()[2 * i] + 0.5, a.data()[2 * i + 1] + 0.5});
               o[2 * i] = w.x(), o[2 * i + 1] = w.y();
             }
             return out;
           }, "cells"_a, "World coordinates (n, 2) of cell centres (n, 2).")
      .def("distance_field",
           [](const OccupancyGrid& g, int threshold) {
             if (threshold < 0 || threshold > 127) throw std::invalid_argument("threshold must be in 0..127");
             return mat_to_numpy(distance_field(g, static_cast<std::int8_t>(threshold)));
           }, "occupied_threshold"_a = 65,
           "Metres from each cell centre to the nearest obstacle cell centre (float32).")
      .def("extract_window", &extract_window, "center"_a, "width"_a, "height"_a,
           "resolution"_a = 0.0, "A window centred on and aligned with a pose; outside is unknown.")
      .def("copy", &OccupancyGrid::clone);
  bind_ray_casting(cls);
}

void bind_map_image(py::module_& m) {
  m.def("occupancy_from_image",
        [](const py::array& image, double resolution, const Pose2& origin, const std::string& mode,
           bool negate, double occ, double free) {
          return occupancy_from_image(numpy_to_image(image), resolution, origin,
                                      make_params(mode, negate, occ, free));
        },
        "image"_a, "resolution"_a, "origin"_a, "mode"_a = "trinary", "negate"_a = false,
        "occupied_thresh"_a = 0.65, "free_thresh"_a = 0.196);
  m.def("image_from_occupancy",
        [](const OccupancyGrid& g, const std::string& mode, bool negate, double occ, double free) {
          return mat_to_numpy(image_from_occupancy(g, make_params(mode, negate, occ, free)));
        },
        "grid"_a, "mode"_a = "trinary", "negate"_a = false, "occupied_thresh"_a = 0.65,
        "free_thresh"_a = 0.196);
  m.def("read_image", [](const std::string& path) { return mat_to_numpy(read_image(path)); },
        "path"_a, "Reads an image file as stored (OpenCV, channels in B, G, R, A order).");
  m.def("write_image",
        [](const std::string& path, const py::array& image) {
          write_image(path, numpy_to_image(image));
        },
        "path"_a, "image"_a);
}

}  // namespace

void bind_grid(py::module_& m) {
  m.attr("FREE") = kFree;
  m.attr("OCCUPIED") = kOccupied;
  m.attr("UNKNOWN") = kUnknown;
  bind_occupancy_grid(m);
  bind_map_image(m);
}

}  // namespace kiseki::bindings
