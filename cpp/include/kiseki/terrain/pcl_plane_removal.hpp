// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace kiseki {

/// The 3-D alternative with PCL (the design card's choice): normals by pcl::NormalEstimation
/// (k nearest neighbours), then pcl::SACSegmentationFromNormals with a normal-plane model,
/// repeated: each plane of at least `min_inliers` points is removed and the next one searched.
/// RANSAC's draws follow the point order, which is shuffled with `seed` first, so the seed
/// decides them (PCL's own generator has a fixed seed).
struct PclPlaneParams {
  double distance = 0.03;       ///< inlier distance to the plane (m)
  double normal_weight = 0.1;   ///< the normal's share of the point-to-model distance
  int normal_neighbours = 12;   ///< k of the normal estimation
  std::size_t min_inliers = 400;
  int max_planes = 8;
  int max_iterations = 500;
  void validate() const;
};

struct PlaneModel {
  Eigen::Vector4d coefficients = Eigen::Vector4d::Zero();  ///< a x + b y + c z + d = 0, |(a, b, c)| = 1
  std::size_t inliers = 0;
};

struct PclPlaneResult {
  std::vector<std::uint8_t> removed;  ///< per input point
  std::vector<PlaneModel> planes;
};

/// Plane removal on points (3 x n, finite).
PclPlaneResult remove_planes_pcl(const Eigen::Matrix3Xd& points, const PclPlaneParams& params, std::uint64_t seed);

}  // namespace kiseki
