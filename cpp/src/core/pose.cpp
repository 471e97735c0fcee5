// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/pose.hpp"

#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"

namespace kiseki {

Pose2::Pose2(double x_, double y_, double theta_) : x(x_), y(y_), theta(normalize_angle(theta_)) {}

Pose2 Pose2::compose(const Pose2& other) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {x + c * other.x - s * other.y, y + s * other.x + c * other.y, theta + other.theta};
}

Pose2 Pose2::inverse() const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {-(c * x + s * y), -(-s * x + c * y), -theta};
}

Pose2 Pose2::between(const Pose2& other) const { return inverse().compose(other); }

Eigen::Vector2d Pose2::transform_point(const Eigen::Vector2d& p) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return {x + c * p.x() - s * p.y(), y + s * p.x() + c * p.y()};
}

Eigen::Isometry2d Pose2::isometry() const {
  Eigen::Isometry2d iso = Eigen::Isometry2d::Identity();
  iso.translation() = Eigen::Vector2d(x, y);
  iso.linear() = Eigen::Rotation2Dd(theta).toRotationMatrix();
  return iso;
}

Pose3::Pose3(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) : translation(t), rotation(q) {
  const double n = q.norm();
  if (!(n > 1e-12) || !std::isfinite(n)) {
    throw std::invalid_argument("Pose3: rotation quaternion must be finite and non-zero");
  }
  rotation.normalize();
}

Pose3 Pose3::from_rpy(double x, double y, double z, double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return {Eigen::Vector3d(x, y, z), q};
}

Pose3 Pose3::compose(const Pose3& other) const {
  return {translation + rotation * other.translation, rotation * other.rotation};
}

Pose3 Pose3::inverse() const {
  const Eigen::Quaterniond qi = rotation.conjugate();
  return {-(qi * translation), qi};
}

Eigen::Vector3d Pose3::transform_point(const Eigen::Vector3d& p) const {
  return translation + rotation * p;
}

Eigen::Isometry3d Pose3::isometry() const {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.translation() = translation;
  iso.linear() = rotation.toRotationMatrix();
  return iso;
}

double Pose3::yaw() const {
  const Eigen::Vector3d fwd = rotation * Eigen::Vector3d::UnitX();
  return std::atan2(fwd.y(), fwd.x());
}

Pose2 Pose3::to_pose2() const { return {translation.x(), translation.y(), yaw()}; }

}  // namespace kiseki
