// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace kiseki {

/// A pose in the plane: position (x, y) in metres and heading theta in radians,
/// theta kept in [-pi, pi).
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2() = default;
  Pose2(double x_, double y_, double theta_);

  /// this (+) other: other expressed in this pose's frame, returned in the parent frame.
  Pose2 compose(const Pose2& other) const;
  /// The inverse pose, so that p.compose(p.inverse()) is the identity.
  Pose2 inverse() const;
  /// Relative pose of other seen from this pose: inverse() (+) other.
  Pose2 between(const Pose2& other) const;
  /// Maps a point from this pose's frame to the parent frame.
  Eigen::Vector2d transform_point(const Eigen::Vector2d& p) const;
  Eigen::Vector3d vector() const { return {x, y, theta}; }
  Eigen::Isometry2d isometry() const;
};

/// A rigid pose in space, rotation as a unit quaternion.
struct Pose3 {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  Pose3() = default;
  Pose3(const Eigen::Vector3d& t, const Eigen::Quaterniond& q);
  /// From roll, pitch, yaw (radians, applied as Rz(yaw) * Ry(pitch) * Rx(roll)).
  static Pose3 from_rpy(double x, double y, double z, double roll, double pitch, double yaw);

  Pose3 compose(const Pose3& other) const;
  Pose3 inverse() const;
  Eigen::Vector3d transform_point(const Eigen::Vector3d& p) const;
  Eigen::Isometry3d isometry() const;
  /// Yaw of the rotation (heading of the body x axis projected on the ground plane).
  double yaw() const;
  /// Drops height, roll and pitch.
  Pose2 to_pose2() const;
};

}  // namespace kiseki
