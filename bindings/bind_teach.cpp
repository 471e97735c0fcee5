// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/local_map.hpp"
#include "kiseki/teach/evidence_map.hpp"
#include "kiseki/teach/map_merge.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

void bind_teach(py::module_& m) {
  m.def("merge_local_map", &merge_local_map, "environment"_a, "local"_a, "pose"_a,
        "Places a local map in the environment map with the thesis' merge rules.");
  py::class_<EvidenceMap>(m, "EvidenceMap")
      .def(py::init<const OccupancyGrid&>(), "frame"_a)
      .def(
          "merge",
          [](EvidenceMap& e, const LocalMapBuilder& local, const Pose2& pose) {
            py::gil_scoped_release release;
            return e.merge(local.build(), local.hits(), pose);
          },
          "local"_a, "pose"_a,
          "Places the local map of a filled LocalMapBuilder at pose; returns the cells changed.")
      .def("map", &EvidenceMap::map)
      .def_property_readonly("free_counts",
                             [](const EvidenceMap& e) { return mat_to_numpy(e.free_counts().clone()); })
      .def_property_readonly("hit_counts",
                             [](const EvidenceMap& e) { return mat_to_numpy(e.hit_counts().clone()); });
}

}  // namespace kiseki::bindings
