// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <string>

namespace octomap {
class OcTree;
}

namespace kiseki {

/// The rubble paper's global map (Fig. 1: each local map, placed at its estimated pose, is
/// merged into the global one), held in an OctoMap OcTree: every point of a sweep is a ray from
/// the sensor, its end voxel occupied and the voxels it crosses free (OctoMap's log-odds
/// update). Saved as a .bt file that octovis opens.
class GlobalVoxelMap {
 public:
  /// resolution: voxel edge (m); max_range: rays are cut there (the paper's 5 m).
  GlobalVoxelMap(double resolution, double max_range);
  GlobalVoxelMap(GlobalVoxelMap&&) noexcept;
  GlobalVoxelMap& operator=(GlobalVoxelMap&&) noexcept;
  ~GlobalVoxelMap();

  /// Inserts points (3 x n, sensor frame, finite) seen from `sensor_pose` (world from sensor).
  /// discretize: OctoMap's faster mode that casts one ray per end voxel instead of per point
  /// (the same map up to rays sharing an end voxel).
  void insert(const Eigen::Matrix3Xd& points, const Eigen::Isometry3d& sensor_pose, bool discretize = true);
  double resolution() const;
  std::size_t occupied_leaves() const;
  std::size_t free_leaves() const;
  /// Centres of the occupied leaves (3 x n, expanded to the finest voxels).
  Eigen::Matrix3Xd occupied_centres() const;
  /// Writes the tree as an OctoMap binary file, to a temporary file renamed over `path`.
  void write_binary(const std::string& path) const;

 private:
  std::unique_ptr<octomap::OcTree> tree_;
  double max_range_;
};

}  // namespace kiseki
