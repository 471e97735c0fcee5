// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>

namespace kiseki {

/// A PCD file's points (PCL's point cloud format, read and written by PCL's own io).
struct PcdCloud {
  Eigen::Matrix3Xd points;    ///< the finite x, y, z of the file's points
  std::size_t width = 0;      ///< as in the header; an organized cloud has height > 1
  std::size_t height = 0;
  std::size_t non_finite = 0; ///< points dropped for NaN or infinite coordinates (organized clouds' holes)
};

/// Reads x, y, z of any PCD file with those fields (ASCII, binary or binary_compressed; kiseki's
/// own reader, hardened against damaged files, see pcd_file.cpp).
/// Throws std::runtime_error naming the file when it is missing, unreadable, truncated or has
/// no x, y, z fields.
PcdCloud read_pcd(const std::string& path);

/// Writes points (3 x n, finite) as a binary PCD file of PointXYZ, to a temporary file renamed
/// over `path` when complete. Throws std::invalid_argument for non-finite points and
/// std::runtime_error naming the file when it cannot be written.
void write_pcd(const std::string& path, const Eigen::Matrix3Xd& points);

}  // namespace kiseki
