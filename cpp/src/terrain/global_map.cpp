// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/global_map.hpp"

#include "kiseki/io/octomap_file.hpp"

#include <octomap/OcTree.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kiseki {

GlobalVoxelMap::GlobalVoxelMap(double resolution, double max_range) : max_range_(max_range) {
  if (!(std::isfinite(resolution) && resolution >= 0.005 && resolution <= 10.0)) {
    throw std::invalid_argument("global map: resolution must be in 0.005..10 m, got " + std::to_string(resolution));
  }
  if (!(std::isfinite(max_range) && max_range > 0)) {
    throw std::invalid_argument("global map: max_range must be > 0, got " + std::to_string(max_range));
  }
  tree_ = std::make_unique<octomap::OcTree>(resolution);
}

GlobalVoxelMap::GlobalVoxelMap(GlobalVoxelMap&&) noexcept = default;
GlobalVoxelMap& GlobalVoxelMap::operator=(GlobalVoxelMap&&) noexcept = default;
GlobalVoxelMap::~GlobalVoxelMap() = default;

void GlobalVoxelMap::insert(const Eigen::Matrix3Xd& points, const Eigen::Isometry3d& sensor_pose, bool discretize) {
  if (!points.allFinite()) throw std::invalid_argument("global map: the points hold NaN or infinity");
  if (!sensor_pose.matrix().allFinite()) throw std::invalid_argument("global map: the sensor pose holds NaN");
  // OctoMap's addressable cube is 2^16 voxels wide, centred on the origin.
  const double reach = tree_->getResolution() * 32000.0;
  if ((sensor_pose.translation().cwiseAbs().array() > reach).any()) {
    throw std::invalid_argument("global map: the sensor pose is outside OctoMap's addressable range");
  }
  octomap::Pointcloud cloud;
  cloud.reserve(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = sensor_pose * Eigen::Vector3d(points.col(i));
    cloud.push_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  }
  const Eigen::Vector3d o = sensor_pose.translation();
  tree_->insertPointCloud(cloud, octomap::point3d(static_cast<float>(o.x()), static_cast<float>(o.y()),
                                                  static_cast<float>(o.z())),
                          max_range_, false, discretize);
}

double GlobalVoxelMap::resolution() const { return tree_->getResolution(); }

std::size_t GlobalVoxelMap::occupied_leaves() const {
  std::size_t n = 0;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) n += tree_->isNodeOccupied(*it);
  return n;
}

std::size_t GlobalVoxelMap::free_leaves() const {
  std::size_t n = 0;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) n += !tree_->isNodeOccupied(*it);
  return n;
}

Eigen::Matrix3Xd GlobalVoxelMap::occupied_centres() const {
  std::vector<Eigen::Vector3d> centres;
  const double res = tree_->getResolution();
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
    if (!tree_->isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    const int n = static_cast<int>(std::lround(size / res));
    const Eigen::Vector3d corner = Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - Eigen::Vector3d::Constant(size / 2);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) centres.push_back(corner + res * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
  }
  Eigen::Matrix3Xd out(3, static_cast<Eigen::Index>(centres.size()));
  for (std::size_t i = 0; i < centres.size(); ++i) out.col(static_cast<Eigen::Index>(i)) = centres[i];
  return out;
}

void GlobalVoxelMap::write_binary(const std::string& path) const {
  // as OctoMap's writeBinary writes a tree (maximum likelihood, pruned), on a copy so that this
  // map keeps its leaves as they are
  octomap::OcTree copy(*tree_);
  copy.toMaxLikelihood();
  copy.prune();
  write_octomap_binary(copy, path);
}

}  // namespace kiseki
