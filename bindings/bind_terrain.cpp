// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The rubble paper's sphere elevation maps (S-DEM), plane removal and correlation search, and
// PCD files (the io area's only binding so far).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <string>

#include "kiseki/io/pcd_file.hpp"
#include "kiseki/terrain/correlation_search.hpp"
#include "kiseki/terrain/global_map.hpp"
#include "kiseki/terrain/hough_line_removal.hpp"
#include "kiseki/terrain/pcl_plane_removal.hpp"
#include "kiseki/terrain/pcl_registration.hpp"
#include "kiseki/terrain/sphere_elevation_map.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

/// (n, 3) finite points -> 3 x n.
Eigen::Matrix3Xd points_of(const py::handle& obj, const char* name) {
  const DoubleArray a = as_doubles(obj, name);
  require_shape(a, name, 2, 3);
  require_finite(a, name);
  Eigen::Matrix3Xd p(3, a.shape(0));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i) p.col(i) << r(i, 0), r(i, 1), r(i, 2);
  return p;
}

py::array_t<double> points_array(const Eigen::Matrix3Xd& p) {
  py::array_t<double> out({static_cast<py::ssize_t>(p.cols()), py::ssize_t{3}});
  auto w = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < p.cols(); ++i) w(i, 0) = p(0, i), w(i, 1) = p(1, i), w(i, 2) = p(2, i);
  return out;
}

Eigen::Matrix3d rotation_of(const py::object& obj, const char* name) {
  if (obj.is_none()) return Eigen::Matrix3d::Identity();
  const DoubleArray a = as_doubles(obj, name);
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    throw std::invalid_argument(std::string(name) + ": expected a 3 x 3 rotation matrix, got shape " + shape_string(a));
  }
  require_finite(a, name);
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = a.at(i, j);
  return r;
}

py::array_t<double> ranges_array(const SphereElevationMap& map) {
  const auto& g = map.grid();
  py::array_t<double> out({static_cast<py::ssize_t>(g.rows()), static_cast<py::ssize_t>(g.cols())});
  std::copy(map.ranges().begin(), map.ranges().end(), out.mutable_data());
  return out;
}

template <typename T>
py::array_t<bool> mask_array(const std::vector<T>& mask, py::ssize_t rows, py::ssize_t cols) {
  py::array_t<bool> out = cols > 0 ? py::array_t<bool>({rows, cols}) : py::array_t<bool>(rows);
  bool* w = out.mutable_data();
  for (std::size_t i = 0; i < mask.size(); ++i) w[i] = mask[i] != 0;
  return out;
}

CorrelationCost cost_of(const std::string& name) {
  if (name == "mean") return CorrelationCost::mean;
  if (name == "sum") return CorrelationCost::sum;
  throw std::invalid_argument("cost must be 'mean' or 'sum', got '" + name + "'");
}

py::dict result_dict(CorrelationResult r) {
  py::dict d;
  d["translation"] = Eigen::Vector3d(r.translation);
  d["cost"] = r.cost;
  d["overlap"] = r.overlap;
  d["index"] = r.index;
  d["evaluated"] = r.evaluated;
  if (!r.costs.empty()) {
    auto* owned = new std::vector<double>(std::move(r.costs));
    py::capsule keep(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
    d["costs"] = py::array_t<double>(static_cast<py::ssize_t>(owned->size()), owned->data(), keep);
  }
  return d;
}

}  // namespace

void bind_terrain(py::module_& m) {
  py::class_<SphereGrid>(m, "SphereGrid")
      .def(py::init<>())
      .def_readwrite("theta_min_deg", &SphereGrid::theta_min_deg)
      .def_readwrite("theta_max_deg", &SphereGrid::theta_max_deg)
      .def_readwrite("phi_min_deg", &SphereGrid::phi_min_deg)
      .def_readwrite("phi_max_deg", &SphereGrid::phi_max_deg)
      .def_readwrite("step_deg", &SphereGrid::step_deg)
      .def_readwrite("max_range", &SphereGrid::max_range)
      .def("validate", &SphereGrid::validate)
      .def_property_readonly("rows", &SphereGrid::rows)
      .def_property_readonly("cols", &SphereGrid::cols)
      .def("theta", &SphereGrid::theta, "row"_a)
      .def("phi", &SphereGrid::phi, "col"_a)
      .def("cell_of", &SphereGrid::cell_of, "theta"_a, "phi"_a);

  py::class_<SphereElevationMap>(m, "SphereElevationMap")
      .def(py::init<const SphereGrid&>(), "grid"_a)
      .def_static(
          "from_ranges",
          [](const SphereGrid& grid, const py::handle& ranges) {
            grid.validate();
            const DoubleArray a = as_doubles(ranges, "ranges");
            if (a.ndim() != 2 || a.shape(0) != grid.rows() || a.shape(1) != grid.cols()) {
              throw std::invalid_argument("ranges: expected shape (" + std::to_string(grid.rows()) + ", " +
                                          std::to_string(grid.cols()) + "), got " + shape_string(a));
            }
            return SphereElevationMap::from_ranges(grid, std::vector<double>(a.data(), a.data() + a.size()));
          },
          "grid"_a, "ranges"_a)
      .def_static(
          "from_points",
          [](const SphereGrid& grid, const py::handle& points, const py::object& attitude) {
            const Eigen::Matrix3Xd p = points_of(points, "points");
            const Eigen::Matrix3d r = rotation_of(attitude, "attitude");
            py::gil_scoped_release release;
            return SphereElevationMap::from_points(grid, p, r);
          },
          "grid"_a, "points"_a, "attitude"_a = py::none())
      .def_static("median", &SphereElevationMap::median, "sweeps"_a)
      .def_property_readonly("grid", &SphereElevationMap::grid)
      .def_property_readonly("ranges", &ranges_array)
      .def_property_readonly("valid_cells", &SphereElevationMap::valid_cells)
      .def("to_points",
           [](const SphereElevationMap& map) {
             std::vector<long> cells;
             const Eigen::Matrix3Xd p = map.to_points(&cells);
             return py::make_tuple(points_array(p), py::array_t<long>(static_cast<py::ssize_t>(cells.size()), cells.data()));
           })
      .def("rotated", [](const SphereElevationMap& map, const py::handle& r) {
        return map.rotated(rotation_of(py::reinterpret_borrow<py::object>(r), "rotation"));
      }, "rotation"_a);

  py::class_<TranslationGrid>(m, "TranslationGrid")
      .def(py::init<>())
      .def_readwrite("x_min", &TranslationGrid::x_min)
      .def_readwrite("x_max", &TranslationGrid::x_max)
      .def_readwrite("y_min", &TranslationGrid::y_min)
      .def_readwrite("y_max", &TranslationGrid::y_max)
      .def_readwrite("z_min", &TranslationGrid::z_min)
      .def_readwrite("z_max", &TranslationGrid::z_max)
      .def_readwrite("step", &TranslationGrid::step)
      .def("validate", &TranslationGrid::validate)
      .def_property_readonly("shape", [](const TranslationGrid& g) { return py::make_tuple(g.nx(), g.ny(), g.nz()); })
      .def_property_readonly("size", &TranslationGrid::size)
      .def("at", [](const TranslationGrid& g, std::size_t k) {
        if (k >= g.size()) throw py::index_error("candidate index out of range");
        return Eigen::Vector3d(g.at(k));
      }, "index"_a);

  py::class_<CorrelationSearch>(m, "CorrelationSearch")
      .def(py::init([](const py::handle& previous, const SphereElevationMap& current, const py::object& rotation,
                       const std::string& cost, std::size_t min_overlap, int threads) {
             CorrelationOptions o;
             o.cost = cost_of(cost);
             o.min_overlap = min_overlap;
             o.threads = threads;
             return CorrelationSearch(points_of(previous, "previous_points"), current, rotation_of(rotation, "rotation"), o);
           }),
           "previous_points"_a, "current"_a, "rotation"_a = py::none(), "cost"_a = "mean", "min_overlap"_a = 50,
           "threads"_a = 0)
      .def("cost",
           [](const CorrelationSearch& s, const Eigen::Vector3d& t) {
             std::size_t overlap = 0;
             const double c = s.cost(t, &overlap);
             return py::make_tuple(c, overlap);
           }, "translation"_a)
      .def("exhaustive",
           [](const CorrelationSearch& s, const TranslationGrid& g) {
             CorrelationResult r;
             {
               py::gil_scoped_release release;
               r = s.exhaustive(g);
             }
             return result_dict(std::move(r));
           }, "grid"_a)
      .def("coarse_to_fine",
           [](const CorrelationSearch& s, const TranslationGrid& g, int coarse, std::size_t keep) {
             CorrelationResult r;
             {
               py::gil_scoped_release release;
               r = s.coarse_to_fine(g, coarse, keep);
             }
             return result_dict(std::move(r));
           }, "grid"_a, "coarse"_a = 8, "keep"_a = 16)
      .def_property_readonly("points", &CorrelationSearch::points);

  py::class_<HoughLineParams>(m, "HoughLineParams")
      .def(py::init<>())
      .def_readwrite("angle_step_deg", &HoughLineParams::angle_step_deg)
      .def_readwrite("rho_step", &HoughLineParams::rho_step)
      .def_readwrite("inlier_distance", &HoughLineParams::inlier_distance)
      .def_readwrite("min_votes", &HoughLineParams::min_votes)
      .def_readwrite("max_lines", &HoughLineParams::max_lines)
      .def("validate", &HoughLineParams::validate);
  m.def(
      "remove_lines_hough",
      [](const SphereElevationMap& map, const HoughLineParams& p) {
        HoughRemovalResult r{map, {}, 0};
        {
          py::gil_scoped_release release;
          r = remove_lines_hough(map, p);
        }
        return py::make_tuple(r.kept, mask_array(r.removed, map.grid().rows(), map.grid().cols()), r.lines);
      },
      "map"_a, "params"_a, "(map without the lines' cells, removed mask (rows, cols), lines found).");

  py::class_<PclPlaneParams>(m, "PclPlaneParams")
      .def(py::init<>())
      .def_readwrite("distance", &PclPlaneParams::distance)
      .def_readwrite("normal_weight", &PclPlaneParams::normal_weight)
      .def_readwrite("normal_neighbours", &PclPlaneParams::normal_neighbours)
      .def_readwrite("min_inliers", &PclPlaneParams::min_inliers)
      .def_readwrite("max_planes", &PclPlaneParams::max_planes)
      .def_readwrite("max_iterations", &PclPlaneParams::max_iterations)
      .def("validate", &PclPlaneParams::validate);
  m.def(
      "remove_planes_pcl",
      [](const py::handle& points, const PclPlaneParams& p, std::uint64_t seed) {
        const Eigen::Matrix3Xd pts = points_of(points, "points");
        PclPlaneResult r;
        {
          py::gil_scoped_release release;
          r = remove_planes_pcl(pts, p, seed);
        }
        py::array_t<double> planes({static_cast<py::ssize_t>(r.planes.size()), py::ssize_t{4}});
        py::array_t<long> inliers(static_cast<py::ssize_t>(r.planes.size()));
        auto w = planes.mutable_unchecked<2>();
        for (std::size_t k = 0; k < r.planes.size(); ++k) {
          for (int j = 0; j < 4; ++j) w(k, j) = r.planes[k].coefficients[j];
          inliers.mutable_data()[k] = static_cast<long>(r.planes[k].inliers);
        }
        return py::make_tuple(mask_array(r.removed, static_cast<py::ssize_t>(r.removed.size()), 0), planes, inliers);
      },
      "points"_a, "params"_a, "seed"_a, "(removed mask (n,), planes (k, 4) as a x + b y + c z + d = 0, inliers (k,)).");

  py::class_<GlobalVoxelMap>(m, "GlobalVoxelMap")
      .def(py::init<double, double>(), "resolution"_a, "max_range"_a)
      .def(
          "insert",
          [](GlobalVoxelMap& map, const py::handle& points, const py::handle& pose, bool discretize) {
            const Eigen::Matrix3Xd p = points_of(points, "points");
            const DoubleArray a = as_doubles(pose, "sensor_pose");
            if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) {
              throw std::invalid_argument("sensor_pose: expected a 4 x 4 matrix, got shape " + shape_string(a));
            }
            require_finite(a, "sensor_pose");
            Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
            for (int i = 0; i < 3; ++i) {
              for (int j = 0; j < 4; ++j) t.matrix()(i, j) = a.at(i, j);
            }
            py::gil_scoped_release release;
            map.insert(p, t, discretize);
          },
          "points"_a, "sensor_pose"_a, "discretize"_a = true)
      .def_property_readonly("resolution", &GlobalVoxelMap::resolution)
      .def_property_readonly("occupied_leaves", &GlobalVoxelMap::occupied_leaves)
      .def_property_readonly("free_leaves", &GlobalVoxelMap::free_leaves)
      .def("occupied_centres", [](const GlobalVoxelMap& map) { return points_array(map.occupied_centres()); })
      .def("write_binary", &GlobalVoxelMap::write_binary, "path"_a);

  m.attr("PCL_COORDINATE_LIMIT") = kPclCoordinateLimit;
  m.def(
      "register_pcl",
      [](const py::handle& source, const py::handle& target, const py::handle& initial, const std::string& method,
         double max_correspondence, int max_iterations) {
        const Eigen::Matrix3Xd s = points_of(source, "source"), t = points_of(target, "target");
        const DoubleArray a = as_doubles(initial, "initial");
        if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) {
          throw std::invalid_argument("initial: expected a 4 x 4 matrix, got shape " + shape_string(a));
        }
        require_finite(a, "initial");
        Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 4; ++j) guess.matrix()(i, j) = a.at(i, j);
        }
        PclRegistrationParams p;
        p.method = method;
        p.max_correspondence = max_correspondence;
        p.max_iterations = max_iterations;
        PclRegistrationResult r;
        {
          py::gil_scoped_release release;
          r = register_pcl(s, t, guess, p);
        }
        return py::make_tuple(Eigen::Matrix4d(r.transform.matrix()), r.converged, r.fitness);
      },
      "source"_a, "target"_a, "initial"_a, "method"_a = "gicp", "max_correspondence"_a = 0.5,
      "max_iterations"_a = 50,
      "PCL's ICP or GICP: (4x4 transform mapping source onto target, converged, fitness in m^2).");

  m.def(
      "read_pcd",
      [](const std::string& path) {
        PcdCloud c;
        {
          py::gil_scoped_release release;
          c = read_pcd(path);
        }
        return py::make_tuple(points_array(c.points), c.width, c.height, c.non_finite);
      },
      "path"_a, "(points (n, 3), width, height, points dropped as non-finite).");
  m.def(
      "write_pcd",
      [](const std::string& path, const py::handle& points) {
        const Eigen::Matrix3Xd p = points_of(points, "points");
        py::gil_scoped_release release;
        write_pcd(path, p);
      },
      "path"_a, "points"_a);
}

}  // namespace kiseki::bindings
