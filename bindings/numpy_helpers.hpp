// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// numpy <-> C++ helpers shared by the binding files: shape and value checks that raise
// ValueError (std::invalid_argument) with the argument's name.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <opencv2/core/mat.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "kiseki/core/pose.hpp"

namespace kiseki::bindings {

namespace py = pybind11;
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

inline std::string shape_string(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Checks a numeric array's dimensionality and, where cols >= 0, its last dimension.
template <typename Array>
void require_shape(const Array& a, const char* name, int ndim, py::ssize_t cols = -1) {
  if (a.ndim() != ndim || (cols >= 0 && a.shape(ndim - 1) != cols)) {
    std::string want = ndim == 1 ? "(n,)" : (cols >= 0 ? "(n, " + std::to_string(cols) + ")" : "(n, m)");
    throw std::invalid_argument(std::string(name) + ": expected an array of shape " + want +
                                ", got shape " + shape_string(a));
  }
}

template <typename Array>
void require_finite(const Array& a, const char* name) {
  const auto* p = a.data();
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    if (!std::isfinite(p[i])) {
      throw std::invalid_argument(std::string(name) + ": contains NaN or infinite values");
    }
  }
}

/// Converts any numeric input to a C-contiguous array of T (no copy when it already is one),
/// rejecting non-numeric dtypes (strings, objects) with a ValueError naming the argument.
template <typename T>
py::array_t<T, py::array::c_style | py::array::forcecast> as_numeric(const py::handle& obj,
                                                                      const char* name) {
  py::array raw = py::array::ensure(obj);
  if (!raw) throw std::invalid_argument(std::string(name) + ": expected a numeric array");
  const char kind = raw.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b') {
    throw std::invalid_argument(std::string(name) + ": expected a numeric array, got dtype " +
                                std::string(py::str(raw.dtype())));
  }
  return py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(raw);
}

inline DoubleArray as_doubles(const py::handle& obj, const char* name) {
  return as_numeric<double>(obj, name);
}
inline FloatArray as_floats(const py::handle& obj, const char* name) {
  return as_numeric<float>(obj, name);
}

/// A scan's checked beam angles (n,) and ranges (n,), without a copy when already contiguous.
inline std::pair<DoubleArray, FloatArray> beams(const py::handle& a_in, const py::handle& r_in) {
  auto a = as_doubles(a_in, "angles");
  auto r = as_floats(r_in, "ranges");
  require_shape(a, "angles", 1);
  require_shape(r, "ranges", 1);
  if (a.shape(0) != r.shape(0)) throw std::invalid_argument("angles and ranges differ in length");
  return {a, r};
}

inline Pose2 pose_from_row(const double* row) { return {row[0], row[1], row[2]}; }

/// Hands a cv::Mat to numpy without copying: a capsule keeps the Mat (and so its buffer)
/// alive. The array shares the Mat's buffer: pass a clone of anything still in use in C++.
inline py::array mat_to_numpy(cv::Mat mat) {
  auto* owned = new cv::Mat(std::move(mat));
  py::capsule keep(owned, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto elem = static_cast<py::ssize_t>(owned->elemSize1());
  std::vector<py::ssize_t> shape = {owned->rows, owned->cols};
  std::vector<py::ssize_t> strides = {static_cast<py::ssize_t>(owned->step[0]),
                                      static_cast<py::ssize_t>(owned->elemSize())};
  if (owned->channels() > 1) {
    shape.push_back(owned->channels());
    strides.push_back(elem);
  }
  py::dtype dt;
  switch (owned->depth()) {
    case CV_8U: dt = py::dtype::of<std::uint8_t>(); break;
    case CV_8S: dt = py::dtype::of<std::int8_t>(); break;
    case CV_16U: dt = py::dtype::of<std::uint16_t>(); break;
    case CV_32S: dt = py::dtype::of<std::int32_t>(); break;
    case CV_32F: dt = py::dtype::of<float>(); break;
    default: throw std::runtime_error("unsupported matrix depth");
  }
  return py::array(dt, shape, strides, owned->data, keep);
}

/// A numpy image (uint8 or uint16; (h, w) or (h, w, 1..4), channels in OpenCV's order) copied
/// into a cv::Mat; ValueError naming what is wrong otherwise.
inline cv::Mat numpy_to_image(const py::array& image) {
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

}  // namespace kiseki::bindings
