// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <chrono>
#include <cstring>
#include <ctime>
#include <limits>

#include "kiseki/grid/distance_field.hpp"
#include "kiseki/grid/local_window.hpp"
#include "kiseki/grid/map_image.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "kiseki/grid/sector_caster.hpp"
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
  // the sides as 64-bit integers, the fill as an int, all checked by the constructor once they
  // fit its ints: 2**31 cells across or a fill of 200 were pybind11's list of signatures
  cls.def(py::init([](std::int64_t width, std::int64_t height, double resolution,
                      const Pose2& origin, int fill) {
            constexpr std::int64_t kInt = std::numeric_limits<int>::max();
            if (std::max(width, height) > kInt || std::min(width, height) < -kInt) {
              throw std::invalid_argument("OccupancyGrid: more than 1e9 cells requested (" +
                                          std::to_string(width) + " x " + std::to_string(height) + ")");
            }
            return OccupancyGrid(static_cast<int>(width), static_cast<int>(height), resolution, origin,
                                 fill);
          }),
          "width"_a, "height"_a, "resolution"_a, "origin"_a = Pose2(), "fill"_a = kUnknown)
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
           }, "points"_a,
           "Cells (n, 2) containing world points (n, 2); may lie outside (an index beyond 1e9 "
           "cells is clamped there, outside any map).")
      .def("cell_to_world",
           [](const OccupancyGrid& g, const py::handle& cells) {
             const auto a = as_doubles(cells, "cells");
             require_shape(a, "cells", 2, 2);
             require_finite(a, "cells");  // a NaN cell was a NaN point
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
}

// Seconds of CPU time this thread has used (POSIX): a benchmark's measure on a shared machine,
// where wall time also counts the time other processes hold the core.
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Wall and CPU seconds of fn() on this thread.
template <typename Fn>
py::tuple timed(Fn&& fn) {
  double wall = 0.0, cpu = 0.0;
  {
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu_seconds();
    fn();
    cpu = thread_cpu_seconds() - cpu_start;
    wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return py::make_tuple(wall, cpu);
}

// Every beam of every pose through a caster, row by row: out[i * b + j] is beam j of pose i.
template <typename Caster>
void cast_all(const Caster& c, const double* poses, std::size_t n, const double* angles,
              std::size_t b, double max_range, double* out) {
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = poses + 3 * i;
    for (std::size_t j = 0; j < b; ++j) out[i * b + j] = c.range(p[0], p[1], p[2] + angles[j], max_range);
  }
}

// The casters' Python methods: ranges of scans, and the same casts timed in C++ (seconds on
// this thread, no Python in the loop) for the benchmarks' rays per second.
template <typename Caster, typename Cls>
void bind_caster_methods(Cls& cls) {
  const auto checked = [](const py::handle& poses_in, const py::handle& angles_in, double max_range) {
    auto poses = as_doubles(poses_in, "poses");
    auto angles = as_doubles(angles_in, "angles");
    require_shape(poses, "poses", 2, 3);
    require_shape(angles, "angles", 1);
    require_finite(poses, "poses");
    require_finite(angles, "angles");
    if (!(max_range >= 0.0) || !std::isfinite(max_range)) {
      throw std::invalid_argument("max_range must be finite and >= 0");
    }
    return std::make_pair(poses, angles);
  };
  cls.def(
         "ranges",
         [checked](const Caster& c, const py::handle& poses_in, const py::handle& angles_in,
                   double max_range) {
           const auto [poses, angles] = checked(poses_in, angles_in, max_range);
           const auto n = poses.shape(0), b = angles.shape(0);
           py::array_t<double> out({n, b});
           double* dst = out.mutable_data();
           {
             py::gil_scoped_release release;
             cast_all(c, poses.data(), static_cast<std::size_t>(n), angles.data(),
                      static_cast<std::size_t>(b), max_range, dst);
           }
           return out;
         },
         "poses"_a, "angles"_a, "max_range"_a,
         "Ranges (n, b): beam j leaves sensor pose i (n, 3) at heading theta + angles[j].")
      .def(
          "time_ranges",
          [checked](const Caster& c, const py::handle& poses_in, const py::handle& angles_in,
                    double max_range) {
            const auto [poses, angles] = checked(poses_in, angles_in, max_range);
            const auto n = static_cast<std::size_t>(poses.shape(0));
            const auto b = static_cast<std::size_t>(angles.shape(0));
            std::vector<double> out(n * b);
            return timed([&] { cast_all(c, poses.data(), n, angles.data(), b, max_range, out.data()); });
          },
          "poses"_a, "angles"_a, "max_range"_a,
          "(wall, CPU) seconds that ranges() takes in C++ on this thread (the casts only; for "
          "benchmarks).")
      .def_property_readonly("grid", &Caster::grid);
}

void bind_casters(py::module_& m) {
  py::enum_<RayCasterKind>(m, "RayCaster", "The ray casters of a model (both exact to rounding).")
      .value("distance_field", RayCasterKind::distance_field)
      .value("swept_sector", RayCasterKind::swept_sector);
  const auto threshold = [](int t) {
    if (t < 0 || t > 127) throw std::invalid_argument("occupied_threshold must be in 0..127");
    return static_cast<std::int8_t>(t);
  };
  py::class_<RangeCaster> field(m, "RangeCaster",
                                "Exact ranges: the cell walk skipping free space with a distance field.");
  field.def(py::init([threshold](const OccupancyGrid& g, bool unknown_stops, int occupied_threshold) {
              return RangeCaster(g, unknown_stops, threshold(occupied_threshold));
            }),
            "grid"_a, "unknown_stops"_a = true, "occupied_threshold"_a = 65);
  bind_caster_methods<RangeCaster>(field);
  py::class_<SectorCaster> sector(
      m, "SectorCaster",
      "Exact ranges: the cell walk jumping over free lines with a swept-sector table.");
  sector
      .def(py::init([threshold](const OccupancyGrid& g, bool unknown_stops, int occupied_threshold,
                                int sectors_per_octant) {
             return SectorCaster(g, unknown_stops, threshold(occupied_threshold), sectors_per_octant);
           }),
           "grid"_a, "unknown_stops"_a = true, "occupied_threshold"_a = 65,
           "sectors_per_octant"_a = 8)
      .def(
          "scans",
          [](const SectorCaster& c, const py::handle& poses_in, const py::handle& angles_in,
             double max_range, bool timed_) -> py::object {
            auto poses = as_doubles(poses_in, "poses");
            auto angles = as_doubles(angles_in, "angles");
            require_shape(poses, "poses", 2, 3);
            require_shape(angles, "angles", 1);
            require_finite(poses, "poses");
            require_finite(angles, "angles");
            const auto n = static_cast<std::size_t>(poses.shape(0));
            const auto b = static_cast<std::size_t>(angles.shape(0));
            std::vector<double> cos_b(b), sin_b(b), reach(b, max_range), out(n * b);
            for (std::size_t j = 0; j < b; ++j) cos_b[j] = std::cos(angles.data()[j]), sin_b[j] = std::sin(angles.data()[j]);
            const auto cast = [&] {
              for (std::size_t i = 0; i < n; ++i) {
                c.scan(pose_from_row(poses.data() + 3 * i), cos_b.data(), sin_b.data(), reach.data(), b,
                       out.data() + i * b);
              }
            };
            if (timed_) return timed(cast);
            {
              py::gil_scoped_release release;
              cast();
            }
            py::array_t<double> ranges({poses.shape(0), angles.shape(0)});
            std::memcpy(ranges.mutable_data(), out.data(), out.size() * sizeof(double));
            return ranges;
          },
          "poses"_a, "angles"_a, "max_range"_a, "timed"_a = false,
          "Ranges (n, b) cast scan by scan (one sine and cosine per pose, as the beam model "
          "casts); timed=True returns the (wall, CPU) seconds the casts took in C++ instead.")
      .def_property_readonly("sectors", &SectorCaster::sectors)
      .def_property_readonly("memory_bytes", &SectorCaster::memory_bytes,
                             "Bytes of the table and mask the caster holds besides the map.");
  bind_caster_methods<SectorCaster>(sector);
}

}  // namespace

void bind_grid(py::module_& m) {
  m.attr("FREE") = kFree;
  m.attr("OCCUPIED") = kOccupied;
  m.attr("UNKNOWN") = kUnknown;
  bind_occupancy_grid(m);
  bind_map_image(m);
  bind_casters(m);
}

}  // namespace kiseki::bindings
