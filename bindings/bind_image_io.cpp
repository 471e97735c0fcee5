// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// kiseki._image_io: image files through OpenCV's codecs, a module of its own so that `import
// kiseki` does not load the codecs' libraries (GDAL and about 140 more on Debian, 0.1 s); the
// map readers and writers import it when they first read or write an image.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "kiseki/io/image_file.hpp"
#include "numpy_helpers.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

PYBIND11_MODULE(_image_io, m) {
  using kiseki::bindings::mat_to_numpy;
  using kiseki::bindings::numpy_to_image;
  m.doc() = "kiseki's image files (private: use kiseki.io.ros_map)";
  m.def(
      "read_image", [](const std::string& path) { return mat_to_numpy(kiseki::read_image(path)); }, "path"_a,
      "Reads an image file as stored (OpenCV, channels in B, G, R, A order).");
  m.def(
      "write_image",
      [](const std::string& path, const py::array& image) { kiseki::write_image(path, numpy_to_image(image)); },
      "path"_a, "image"_a);
}
