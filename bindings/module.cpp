// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/pybind11.h>

namespace kiseki::bindings {
void bind_core(pybind11::module_& m);
void bind_grid(pybind11::module_& m);
void bind_mapping(pybind11::module_& m);
void bind_sim(pybind11::module_& m);
void bind_models(pybind11::module_& m);
void bind_filters(pybind11::module_& m);
void bind_teach(pybind11::module_& m);
void bind_coop(pybind11::module_& m);
void bind_speed(pybind11::module_& m);
void bind_gp(pybind11::module_& m);
void bind_terrain(pybind11::module_& m);
}  // namespace kiseki::bindings

PYBIND11_MODULE(_core, m) {
  m.doc() = "kiseki's C++ core (private: use the kiseki package)";
  kiseki::bindings::bind_core(m);
  kiseki::bindings::bind_grid(m);
  kiseki::bindings::bind_mapping(m);
  kiseki::bindings::bind_sim(m);
  kiseki::bindings::bind_models(m);
  kiseki::bindings::bind_filters(m);
  kiseki::bindings::bind_teach(m);
  kiseki::bindings::bind_coop(m);
  kiseki::bindings::bind_speed(m);
  kiseki::bindings::bind_gp(m);
  kiseki::bindings::bind_terrain(m);
}
