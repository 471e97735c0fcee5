// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <opencv2/core/mat.hpp>

#include "kiseki/core/pose.hpp"
#include "kiseki/sim/world3d.hpp"

namespace kiseki {

/// A pinhole depth camera in the optical convention (z forward, x right, y down).
struct PinholeCamera {
  int width = 160;
  int height = 120;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double min_range = 0.5;   ///< metres along the optical axis (Xtion: 0.5 m)
  double max_range = 10.0;  ///< metres (Xtion: about 10 m)

  /// Intrinsics of an image whose full fields of view (radians) are hfov x vfov.
  static PinholeCamera from_fov(int width, int height, double hfov, double vfov, double min_range,
                                double max_range);
  void validate() const;
};

/// Renders the z-depth (metres along the optical axis) of every pixel by casting its ray into
/// the world. Pixels without a surface between min_range and max_range are 0 (ROS convention:
/// no measurement). `optical_pose` is the optical frame's pose in the world.
cv::Mat render_depth(const World3D& world, const Pose3& optical_pose, const PinholeCamera& camera);

}  // namespace kiseki
