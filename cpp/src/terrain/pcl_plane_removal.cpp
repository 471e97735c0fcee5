// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/pcl_plane_removal.hpp"

#include <pcl/features/normal_3d.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "kiseki/core/random.hpp"

namespace kiseki {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PCL plane removal: " + message);
}

}  // namespace

void PclPlaneParams::validate() const {
  require(std::isfinite(distance) && distance > 0, "distance must be > 0, got " + std::to_string(distance));
  require(std::isfinite(normal_weight) && normal_weight >= 0 && normal_weight <= 1,
          "normal_weight must be in 0..1, got " + std::to_string(normal_weight));
  require(normal_neighbours >= 3, "normal_neighbours must be >= 3");
  require(min_inliers >= 3, "min_inliers must be >= 3 (three points make a plane)");
  require(max_planes >= 0, "max_planes must be >= 0");
  require(max_iterations >= 1, "max_iterations must be >= 1");
}

PclPlaneResult remove_planes_pcl(const Eigen::Matrix3Xd& points, const PclPlaneParams& params, std::uint64_t seed) {
  params.validate();
  require(points.allFinite(), "the points hold NaN or infinity");
  const auto n = static_cast<std::size_t>(points.cols());
  PclPlaneResult result;
  result.removed.assign(n, 0);
  if (n < static_cast<std::size_t>(params.normal_neighbours) + 1 || params.max_planes == 0) return result;

  // The seed decides RANSAC's draws through the order of the points (a Fisher-Yates shuffle).
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  Random rng(seed);
  for (std::size_t i = n - 1; i > 0; --i) std::swap(order[i], order[rng.below(i + 1)]);

  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<Eigen::Index>(order[i]);
    (*cloud)[i] = pcl::PointXYZ(static_cast<float>(points(0, c)), static_cast<float>(points(1, c)),
                                static_cast<float>(points(2, c)));
  }
  auto normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  estimation.setInputCloud(cloud);
  estimation.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  estimation.setKSearch(params.normal_neighbours);
  estimation.compute(*normals);

  pcl::SACSegmentationFromNormals<pcl::PointXYZ, pcl::Normal> segmentation;
  segmentation.setOptimizeCoefficients(true);
  segmentation.setModelType(pcl::SACMODEL_NORMAL_PLANE);
  segmentation.setMethodType(pcl::SAC_RANSAC);
  segmentation.setNormalDistanceWeight(params.normal_weight);
  segmentation.setDistanceThreshold(params.distance);
  segmentation.setMaxIterations(params.max_iterations);
  segmentation.setInputCloud(cloud);
  segmentation.setInputNormals(normals);

  // Indices still in play; points whose normal could not be estimated (NaN) never join a plane.
  auto remaining = pcl::make_shared<pcl::Indices>();
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isfinite((*normals)[i].normal_x)) remaining->push_back(static_cast<pcl::index_t>(i));
  }
  for (int k = 0; k < params.max_planes && remaining->size() >= params.min_inliers; ++k) {
    segmentation.setIndices(remaining);
    pcl::PointIndices inliers;
    pcl::ModelCoefficients coefficients;
    segmentation.segment(inliers, coefficients);
    if (inliers.indices.size() < params.min_inliers || coefficients.values.size() != 4) break;
    PlaneModel plane;
    Eigen::Vector4d c(coefficients.values[0], coefficients.values[1], coefficients.values[2], coefficients.values[3]);
    const double norm = c.head<3>().norm();
    plane.coefficients = norm > 0 ? Eigen::Vector4d(c / norm) : c;
    plane.inliers = inliers.indices.size();
    result.planes.push_back(plane);
    std::vector<char> taken(n, 0);
    for (const auto i : inliers.indices) {
      taken[static_cast<std::size_t>(i)] = 1;
      result.removed[order[static_cast<std::size_t>(i)]] = 1;
    }
    auto next = pcl::make_shared<pcl::Indices>();
    for (const auto i : *remaining) {
      if (!taken[static_cast<std::size_t>(i)]) next->push_back(i);
    }
    remaining = next;
  }
  return result;
}

}  // namespace kiseki
