// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/sim/depth_camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kiseki/sim/box_world.hpp"

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

namespace {

// Image tiles of kTile x kTile pixels, each with the boxes that may be seen through it.
constexpr int kTile = 8;

// For each tile, the indices of the boxes whose projection may cover one of its pixel centres,
// sorted by `nearest` (per box), a z below which no visible point of the box lies: a ray whose
// nearest hit so far is at z_hit stops at the first listed box with nearest >= z_hit.
//
// Conservative, so the image equals one cast per pixel against every box:
// - a pixel's ray has z >= |ray| / norm_max along its range (norm_max: the corner pixel's), so
//   a box farther than eps * norm_max from the camera shows no point with z < eps. Such a box
//   is clipped to z >= eps (eps = min_range / 2), and every visible point of it projects into
//   the rectangle of its clipped corners' projections (a convex set in front of the camera
//   projects to the hull of its vertices' projections: the corners with z >= eps and the
//   crossings of its 12 edges with z = eps), widened by a pixel for rounding; nearest = the
//   larger of eps and its nearest corner's z (z is linear, the box the hull of its corners);
// - a box nearer than that (the camera at or inside it) is listed everywhere, nearest -inf;
// - a box all beyond max_range is listed nowhere (a cast returns at most max_range * norm).
std::vector<std::vector<int>> boxes_per_tile(const BoxWorld& world, const Eigen::Matrix3d& r,
                                             const Eigen::Vector3d& origin,
                                             const PinholeCamera& cam, int tiles_x, int tiles_y,
                                             std::vector<double>& nearest) {
  std::vector<std::vector<int>> tiles(static_cast<std::size_t>(tiles_x) * tiles_y);
  const auto& boxes = world.boxes();
  nearest.assign(boxes.size(), -INFINITY);
  const double eps = std::max(0.5 * cam.min_range, 1e-6);
  const double tx = std::max(cam.cx, cam.width - cam.cx) / cam.fx;
  const double ty = std::max(cam.cy, cam.height - cam.cy) / cam.fy;
  const double near_reach = 1.01 * eps * std::sqrt(1.0 + tx * tx + ty * ty) + 1e-9;
  const double far_z = cam.max_range * (1.0 + 1e-9) + 1e-9;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    const Eigen::Vector3d from_box = b.rotation.transpose() * (origin - b.center);
    const double distance = (from_box.cwiseAbs() - b.half_size).cwiseMax(0.0).norm();
    std::array<Eigen::Vector3d, 8> corners;
    double z_min = INFINITY;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d local((k & 1) ? b.half_size.x() : -b.half_size.x(),
                                  (k & 2) ? b.half_size.y() : -b.half_size.y(),
                                  (k & 4) ? b.half_size.z() : -b.half_size.z());
      corners[k] = r.transpose() * (b.center + b.rotation * local - origin);
      z_min = std::min(z_min, corners[k].z());
    }
    int px0 = 0, px1 = cam.width - 1, py0 = 0, py1 = cam.height - 1;
    if (distance > near_reach) {
      if (z_min >= far_z) continue;
      double u_min = INFINITY, u_max = -INFINITY, v_min = INFINITY, v_max = -INFINITY;
      const auto project = [&](const Eigen::Vector3d& c) {
        const double u = cam.fx * c.x() / c.z() + cam.cx, v = cam.fy * c.y() / c.z() + cam.cy;
        u_min = std::min(u_min, u);
        u_max = std::max(u_max, u);
        v_min = std::min(v_min, v);
        v_max = std::max(v_max, v);
      };
      for (int k = 0; k < 8; ++k) {
        if (corners[k].z() >= eps) project(corners[k]);
        for (int axis = 0; axis < 3; ++axis) {  // the edge to the corner across `axis`
          const int other = k | (1 << axis);
          if (other == k) continue;
          const Eigen::Vector3d& a = corners[k];
          const Eigen::Vector3d& c = corners[other];
          if ((a.z() < eps) != (c.z() < eps)) {
            const double f = (eps - a.z()) / (c.z() - a.z());
            Eigen::Vector3d crossing = a + f * (c - a);
            crossing.z() = eps;
            project(crossing);
          }
        }
      }
      if (!(u_min <= u_max)) continue;  // nothing of the box at z >= eps: nothing visible
      nearest[i] = std::max(eps, z_min);
      // pixel (px, py) looks through (px + 0.5, py + 0.5): the pixels whose centres may fall
      // in [u_min, u_max] x [v_min, v_max], one more on each side
      const double x0 = std::floor(u_min - 0.5) - 1.0, x1 = std::ceil(u_max - 0.5) + 1.0;
      const double y0 = std::floor(v_min - 0.5) - 1.0, y1 = std::ceil(v_max - 0.5) + 1.0;
      if (x1 < 0.0 || y1 < 0.0 || x0 > cam.width - 1.0 || y0 > cam.height - 1.0) continue;
      px0 = static_cast<int>(std::max(0.0, x0));
      py0 = static_cast<int>(std::max(0.0, y0));
      px1 = static_cast<int>(std::min(cam.width - 1.0, x1));
      py1 = static_cast<int>(std::min(cam.height - 1.0, y1));
    }
    for (int ty_ = py0 / kTile; ty_ <= py1 / kTile; ++ty_) {
      for (int tx_ = px0 / kTile; tx_ <= px1 / kTile; ++tx_) {
        tiles[static_cast<std::size_t>(ty_) * tiles_x + tx_].push_back(static_cast<int>(i));
      }
    }
  }
  for (auto& listed : tiles) {
    std::stable_sort(listed.begin(), listed.end(),
                     [&](int a, int b) { return nearest[a] < nearest[b]; });
  }
  return tiles;
}

}  // namespace

cv::Mat render_depth(const World3D& world, const Pose3& optical_pose, const PinholeCamera& cam) {
  cam.validate();
  cv::Mat depth(cam.height, cam.width, CV_32FC1, cv::Scalar(0.0f));
  const Eigen::Matrix3d r = optical_pose.rotation.toRotationMatrix();
  const Eigen::Vector3d origin = optical_pose.translation;
  if (!origin.allFinite() || !r.allFinite()) {
    throw std::invalid_argument("render_depth: the camera pose must be finite");
  }
  // A box world is cast per image tile against the boxes seen through it (a frame of the
  // thesis' factory: 57 boxes, a handful per tile), with the same arithmetic per ray as
  // BoxWorld::cast, so the image is the same to the bit; any other world ray by ray.
  const auto* boxes = dynamic_cast<const BoxWorld*>(&world);
  const int tiles_x = (cam.width + kTile - 1) / kTile, tiles_y = (cam.height + kTile - 1) / kTile;
  std::vector<std::vector<int>> tiles;
  std::vector<double> nearest;
  if (boxes != nullptr) tiles = boxes_per_tile(*boxes, r, origin, cam, tiles_x, tiles_y, nearest);
  for (int v = 0; v < cam.height; ++v) {
    float* row = depth.ptr<float>(v);
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d ray((u + 0.5 - cam.cx) / cam.fx, (v + 0.5 - cam.cy) / cam.fy, 1.0);
      const double norm = ray.norm();  // range along the ray = z-depth * norm
      const Eigen::Vector3d direction = r * (ray / norm);
      double range;
      if (boxes != nullptr) {
        const auto& listed = tiles[static_cast<std::size_t>(v / kTile) * tiles_x + u / kTile];
        const Eigen::Vector3d inv_direction = direction.cwiseInverse();
        range = cam.max_range * norm;
        for (const int box : listed) {
          // a hit in this box or any after it is at range >= nearest * norm (minus the corners'
          // rounding, which the margin covers)
          if (nearest[box] * norm * (1.0 - 1e-9) - 1e-9 >= range) break;  // -inf never breaks
          range = boxes->cast_among(&box, 1, origin, direction, inv_direction, range);
        }
      } else {
        range = world.cast(origin, direction, cam.max_range * norm);
      }
      const double z = range / norm;
      if (z >= cam.min_range && z < cam.max_range) row[u] = static_cast<float>(z);
    }
  }
  return depth;
}

}  // namespace kiseki
