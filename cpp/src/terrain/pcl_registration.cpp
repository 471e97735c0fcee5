// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/pcl_registration.hpp"

#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>

#include <cmath>
#include <stdexcept>

namespace kiseki {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PCL registration: " + message);
}

pcl::PointCloud<pcl::PointXYZ>::Ptr cloud_of(const Eigen::Matrix3Xd& p, const char* name) {
  require(p.allFinite(), std::string(name) + " holds NaN or infinity");
  require(p.size() == 0 || p.cwiseAbs().maxCoeff() <= kPclCoordinateLimit,
          std::string(name) + " holds coordinates beyond +-1e6 m");
  require(p.cols() >= 10, std::string(name) + " has fewer than 10 points");
  auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(static_cast<std::size_t>(p.cols()));
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    (*cloud)[static_cast<std::size_t>(i)] =
        pcl::PointXYZ(static_cast<float>(p(0, i)), static_cast<float>(p(1, i)), static_cast<float>(p(2, i)));
  }
  return cloud;
}

template <typename Registration>
PclRegistrationResult align(Registration& reg, const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                            const Eigen::Isometry3d& initial, const PclRegistrationParams& params) {
  reg.setInputSource(cloud_of(source, "the source"));
  reg.setInputTarget(cloud_of(target, "the target"));
  reg.setMaxCorrespondenceDistance(params.max_correspondence);
  reg.setMaximumIterations(params.max_iterations);
  reg.setTransformationEpsilon(params.transformation_epsilon);
  pcl::PointCloud<pcl::PointXYZ> aligned;
  reg.align(aligned, initial.matrix().cast<float>());
  PclRegistrationResult r;
  r.transform.matrix() = reg.getFinalTransformation().template cast<double>();
  r.converged = reg.hasConverged();
  r.fitness = reg.getFitnessScore(params.max_correspondence);
  return r;
}

}  // namespace

void PclRegistrationParams::validate() const {
  require(method == "icp" || method == "gicp", "method must be icp or gicp, got '" + method + "'");
  require(std::isfinite(max_correspondence) && max_correspondence > 0, "max_correspondence must be > 0");
  require(max_iterations >= 1, "max_iterations must be >= 1");
  require(std::isfinite(transformation_epsilon) && transformation_epsilon >= 0, "transformation_epsilon must be >= 0");
  require(gicp_neighbours >= 3, "gicp_neighbours must be >= 3");
}

PclRegistrationResult register_pcl(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                                   const Eigen::Isometry3d& initial, const PclRegistrationParams& params) {
  params.validate();
  require(initial.matrix().allFinite(), "the initial guess holds NaN");
  // a rigid motion: PCL aligns from any 4 x 4, a scaled or sheared guess gives a result no
  // rotation explains
  const Eigen::Matrix3d r = initial.linear();
  // to 1e-2: a guess chained in float32 (PCL's Matrix4f) or written with 4 decimals is one
  require((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-2 && r.determinant() > 0,
          "the initial guess is not a rigid motion (its 3 x 3 part is not a rotation)");
  require(initial.translation().cwiseAbs().maxCoeff() <= kPclCoordinateLimit,
          "the initial guess moves beyond +-1e6 m");
  if (params.method == "icp") {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    return align(icp, source, target, initial, params);
  }
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
  gicp.setCorrespondenceRandomness(params.gicp_neighbours);
  return align(gicp, source, target, initial, params);
}

}  // namespace kiseki
