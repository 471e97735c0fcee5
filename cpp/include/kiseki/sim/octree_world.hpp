// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <memory>
#include <string>

#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/sim/box_world.hpp"
#include "kiseki/sim/world3d.hpp"

namespace octomap {
class OcTree;
}

namespace kiseki {

/// A world held in an OctoMap OcTree (occupied voxels are surfaces): loaded from a .bt file
/// (e.g. a real building) or voxelised from a BoxWorld, ray cast with OcTree::castRay.
class OctreeWorld : public World3D {
 public:
  /// Reads an OctoMap binary tree (.bt). Throws std::runtime_error naming the file.
  static OctreeWorld read_binary(const std::string& path);
  /// Voxelises every box of a BoxWorld at `resolution` (a voxel is occupied when it overlaps
  /// a box; rotated boxes are over-filled by at most half a voxel).
  static OctreeWorld from_boxes(const BoxWorld& world, double resolution);

  OctreeWorld(OctreeWorld&&) noexcept;
  OctreeWorld& operator=(OctreeWorld&&) noexcept;
  ~OctreeWorld() override;

  double cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
              double max_range) const override;
  Eigen::AlignedBox3d bounds() const override;
  double resolution() const;
  std::size_t occupied_leaves() const;
  /// Writes the tree as an OctoMap binary file (octovis and octomap-tools open it).
  void write_binary(const std::string& path) const;
  /// 2-D ground truth of a height band: a cell is occupied when an occupied voxel whose
  /// centre lies in [z_min, z_max] falls in it; cells with known free voxels only are free,
  /// the rest unknown.
  void rasterize_band(double z_min, double z_max, OccupancyGrid& grid) const;

 private:
  explicit OctreeWorld(std::unique_ptr<octomap::OcTree> tree);
  std::unique_ptr<octomap::OcTree> tree_;
};

}  // namespace kiseki
