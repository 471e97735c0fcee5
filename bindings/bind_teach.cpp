// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <cstring>

#include "kiseki/teach/evidence_map.hpp"
#include "kiseki/teach/map_merge.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

template <typename T>
py::array_t<T> copy_mat(const cv::Mat& mat) {
  py::array_t<T> out({mat.rows, mat.cols});
  for (int y = 0; y < mat.rows; ++y) {
    std::memcpy(out.mutable_data(y, 0), mat.ptr<T>(y), sizeof(T) * static_cast<std::size_t>(mat.cols));
  }
  return out;
}

int merge_evidence(EvidenceMap& m, const OccupancyGrid& local, const py::handle& hits_in,
                   const Pose2& pose) {
  const auto hits = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(hits_in);
  if (!hits || hits.ndim() != 2 || hits.shape(0) != local.height() || hits.shape(1) != local.width()) {
    throw std::invalid_argument("hits: expected a (" + std::to_string(local.height()) + ", " +
                                std::to_string(local.width()) + ") mask of the local map's size");
  }
  const cv::Mat view(local.height(), local.width(), CV_8UC1, const_cast<std::uint8_t*>(hits.data()));
  py::gil_scoped_release release;
  return m.merge(local, view, pose);
}

}  // namespace

void bind_teach(py::module_& m) {
  m.def("merge_local_map", &merge_local_map, "environment"_a, "local"_a, "pose"_a,
        "Places a local map in the environment map with the thesis' merge rules.");
  py::class_<EvidenceMap>(m, "EvidenceMap")
      .def(py::init<const OccupancyGrid&>(), "frame"_a)
      .def("merge", &merge_evidence, "local"_a, "hits"_a, "pose"_a)
      .def("map", &EvidenceMap::map)
      .def_property_readonly("free_counts", [](const EvidenceMap& e) { return copy_mat<std::int32_t>(e.free_counts()); })
      .def_property_readonly("hit_counts", [](const EvidenceMap& e) { return copy_mat<std::int32_t>(e.hit_counts()); });
}

}  // namespace kiseki::bindings
