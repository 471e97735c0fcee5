// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>

#include "kiseki/sim/box_world.hpp"
#include "kiseki/sim/depth_camera.hpp"
#include "kiseki/sim/octree_world.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

std::vector<Box> boxes_from_arrays(const py::handle& c_in, const py::handle& h_in,
                                   const py::handle& r_in) {
  const auto c = as_doubles(c_in, "centers");
  const auto h = as_doubles(h_in, "half_sizes");
  const auto r = as_doubles(r_in, "rotations");
  require_shape(c, "centers", 2, 3);
  require_shape(h, "half_sizes", 2, 3);
  if (r.ndim() != 3 || r.shape(1) != 3 || r.shape(2) != 3) {
    throw std::invalid_argument("rotations: expected shape (n, 3, 3), got " + shape_string(r));
  }
  if (h.shape(0) != c.shape(0) || r.shape(0) != c.shape(0)) {
    throw std::invalid_argument("centers, half_sizes and rotations need the same length");
  }
  std::vector<Box> boxes(static_cast<std::size_t>(c.shape(0)));
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    boxes[i].center = Eigen::Vector3d(c.data() + 3 * i);
    boxes[i].half_size = Eigen::Vector3d(h.data() + 3 * i);
    boxes[i].rotation = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data() + 9 * i);
  }
  return boxes;
}

py::array_t<double> cast_many(const World3D& w, const py::handle& o_in, const py::handle& d_in,
                              double max_range) {
  const auto o = as_doubles(o_in, "origins");
  const auto d = as_doubles(d_in, "directions");
  require_shape(o, "origins", 2, 3);
  require_shape(d, "directions", 2, 3);
  if (o.shape(0) != d.shape(0)) throw std::invalid_argument("origins and directions differ in length");
  if (!(max_range > 0.0) || !std::isfinite(max_range)) throw std::invalid_argument("max_range must be positive");
  require_finite(o, "origins");
  require_finite(d, "directions");
  py::array_t<double> out(o.shape(0));
  double* dst = out.mutable_data();
  {
    py::gil_scoped_release release;
    w.cast_many(o.data(), d.data(), static_cast<std::size_t>(o.shape(0)), max_range, dst);
  }
  return out;
}

Pose3 pose_from_matrix(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) throw std::invalid_argument("pose: matrix must be finite");
  const Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || r.determinant() < 0) {
    throw std::invalid_argument("pose: the 3x3 block must be a rotation matrix");
  }
  return {m.block<3, 1>(0, 3), Eigen::Quaterniond(r)};
}

}  // namespace

void bind_sim(py::module_& m) {
  py::class_<World3D>(m, "World3D")
      .def("cast_many", &cast_many, "origins"_a, "directions"_a, "max_range"_a,
           "Ranges of rays (n, 3) origins along unit directions (n, 3); releases the GIL.")
      .def_property_readonly("bounds", [](const World3D& w) {
        const auto b = w.bounds();
        return py::make_tuple(Eigen::Vector3d(b.min()), Eigen::Vector3d(b.max()));
      })
      .def(
          "render_depth",
          [](const World3D& w, const Eigen::Matrix4d& optical_pose, int width, int height,
             double fx, double fy, double cx, double cy, double min_range, double max_range) {
            PinholeCamera cam{width, height, fx, fy, cx, cy, min_range, max_range};
            const Pose3 pose = pose_from_matrix(optical_pose);
            cv::Mat depth;
            {
              py::gil_scoped_release release;
              depth = render_depth(w, pose, cam);
            }
            py::array_t<float> out({depth.rows, depth.cols});
            std::memcpy(out.mutable_data(), depth.data, sizeof(float) * depth.total());
            return out;
          },
          "optical_pose"_a, "width"_a, "height"_a, "fx"_a, "fy"_a, "cx"_a, "cy"_a, "min_range"_a,
          "max_range"_a, "z-depth image (float32, 0 = no return) of a pinhole camera.");

  py::class_<BoxWorld, World3D>(m, "BoxWorld")
      .def(py::init([](const py::handle& c, const py::handle& h, const py::handle& r) {
             return BoxWorld(boxes_from_arrays(c, h, r));
           }),
           "centers"_a, "half_sizes"_a, "rotations"_a)
      .def_property_readonly("box_count", [](const BoxWorld& w) { return w.boxes().size(); })
      .def("occupied",
           [](const BoxWorld& w, const py::handle& pts) {
             const auto p = as_doubles(pts, "points");
             require_shape(p, "points", 2, 3);
             require_finite(p, "points");
             py::array_t<bool> out(p.shape(0));
             for (py::ssize_t i = 0; i < p.shape(0); ++i) {
               out.mutable_data()[i] = w.occupied(Eigen::Vector3d(p.data() + 3 * i));
             }
             return out;
           }, "points"_a)
      .def("rasterize_band", &BoxWorld::rasterize_band, "z_min"_a, "z_max"_a, "grid"_a,
           py::call_guard<py::gil_scoped_release>());

  py::class_<OctreeWorld, World3D>(m, "OctreeWorld")
      .def_static("read_binary", &OctreeWorld::read_binary, "path"_a)
      .def_static("from_boxes", &OctreeWorld::from_boxes, "world"_a, "resolution"_a,
                  py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("resolution", &OctreeWorld::resolution)
      .def_property_readonly("occupied_leaves", &OctreeWorld::occupied_leaves)
      .def("write_binary", &OctreeWorld::write_binary, "path"_a)
      .def("rasterize_band", &OctreeWorld::rasterize_band, "z_min"_a, "z_max"_a, "grid"_a,
           py::call_guard<py::gil_scoped_release>());
}

}  // namespace kiseki::bindings
