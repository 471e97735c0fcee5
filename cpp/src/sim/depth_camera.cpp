// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/sim/depth_camera.hpp"

#include <cmath>
#include <stdexcept>

namespace kiseki {

PinholeCamera PinholeCamera::from_fov(int width, int height, double hfov, double vfov,
                                      double min_range, double max_range) {
  PinholeCamera c;
  c.width = width;
  c.height = height;
  if (!(hfov > 0.0 && hfov < 3.1) || !(vfov > 0.0 && vfov < 3.1)) {
    throw std::invalid_argument("PinholeCamera: fields of view must lie in (0, 3.1) rad");
  }
  c.fx = 0.5 * width / std::tan(0.5 * hfov);
  c.fy = 0.5 * height / std::tan(0.5 * vfov);
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  c.min_range = min_range;
  c.max_range = max_range;
  c.validate();
  return c;
}

void PinholeCamera::validate() const {
  if (width < 1 || height < 1 || width > 8192 || height > 8192) {
    throw std::invalid_argument("PinholeCamera: image size must be 1..8192 pixels per side");
  }
  if (!(fx > 0.0) || !(fy > 0.0) || !std::isfinite(cx) || !std::isfinite(cy)) {
    throw std::invalid_argument("PinholeCamera: focal lengths must be positive");
  }
  if (!(min_range >= 0.0) || !(max_range > min_range) || !std::isfinite(max_range)) {
    throw std::invalid_argument("PinholeCamera: need 0 <= min_range < max_range");
  }
}

cv::Mat render_depth(const World3D& world, const Pose3& optical_pose, const PinholeCamera& cam) {
  cam.validate();
  cv::Mat depth(cam.height, cam.width, CV_32FC1, cv::Scalar(0.0f));
  const Eigen::Matrix3d r = optical_pose.rotation.toRotationMatrix();
  const Eigen::Vector3d origin = optical_pose.translation;
  for (int v = 0; v < cam.height; ++v) {
    float* row = depth.ptr<float>(v);
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray((u + 0.5 - cam.cx) / cam.fx, (v + 0.5 - cam.cy) / cam.fy, 1.0);
      const double norm = ray.norm();  // range along the ray = z-depth * norm
      const double range = world.cast(origin, r * (ray / norm), cam.max_range * norm);
      const double z = range / norm;
      if (z >= cam.min_range && z < cam.max_range) row[u] = static_cast<float>(z);
    }
  }
  return depth;
}

}  // namespace kiseki
