// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace kiseki {

/// m: the largest coordinate a cloud given to PCL may hold. PCL holds points as float: far beyond
/// a sensor's reach its squared distances overflow and its search aborts the process (an
/// assertion on "NaN, Inf" coordinates, from 1e20 m). Bound as
/// `kiseki._core.PCL_COORDINATE_LIMIT`, also the bound of the text clouds' points and origins.
inline constexpr double kPclCoordinateLimit = 1e6;

/// PCL's scan registration, the baselines the rubble paper's correlation search is compared
/// with on the same scan pairs: pcl::IterativeClosestPoint (point to point) and
/// pcl::GeneralizedIterativeClosestPoint (plane to plane, Segal et al. 2009).
struct PclRegistrationParams {
  std::string method = "gicp";           ///< "icp" or "gicp"
  double max_correspondence = 0.5;       ///< m: pairs farther apart are not used
  int max_iterations = 50;
  double transformation_epsilon = 1e-8;  ///< convergence: squared change of the transform
  int gicp_neighbours = 20;              ///< k of GICP's covariances
  void validate() const;
};

struct PclRegistrationResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< maps source points onto the target
  bool converged = false;
  double fitness = 0.0;  ///< mean squared distance of the matched pairs (m^2)
};

/// Aligns `source` (3 x n) to `target` (3 x m) starting from `initial`. Throws
/// std::invalid_argument for bad parameters, NaN points or clouds of fewer than 10 points.
PclRegistrationResult register_pcl(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target,
                                   const Eigen::Isometry3d& initial, const PclRegistrationParams& params);

}  // namespace kiseki
