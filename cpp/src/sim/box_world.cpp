// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/sim/box_world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace kiseki {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Slab test of a ray against an axis-aligned box; returns the entry distance or +inf.
double ray_aabb(const Eigen::Vector3d& o, const Eigen::Vector3d& inv_d,
                const Eigen::AlignedBox3d& b, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    double ta = (b.min()[k] - o[k]) * inv_d[k];
    double tb = (b.max()[k] - o[k]) * inv_d[k];
    if (std::isnan(ta) || std::isnan(tb)) {  // direction 0 and origin on the slab plane
      if (o[k] < b.min()[k] || o[k] > b.max()[k]) return kInf;
      continue;
    }
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  return t0;
}

}  // namespace

void World3D::cast_many(const double* origins, const double* directions, std::size_t n,
                        double max_range, double* out) const {
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d o(origins + 3 * i), d(directions + 3 * i);
    out[i] = cast(o, d, max_range);
  }
}

Eigen::AlignedBox3d Box::aabb() const {
  const Eigen::Vector3d extent = rotation.cwiseAbs() * half_size;
  return {center - extent, center + extent};
}

bool Box::contains(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d local = rotation.transpose() * (p - center);
  return (local.cwiseAbs().array() <= half_size.array()).all();
}

double Box::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  const Eigen::Vector3d o = rotation.transpose() * (origin - center);
  const Eigen::Vector3d d = rotation.transpose() * direction;
  const Eigen::AlignedBox3d local(-half_size, half_size);
  return ray_aabb(o, d.cwiseInverse(), local, kInf);
}

BoxWorld::BoxWorld(std::vector<Box> boxes) : boxes_(std::move(boxes)) {
  for (const Box& b : boxes_) {
    if (!b.center.allFinite() || !b.half_size.allFinite() || !b.rotation.allFinite() ||
        (b.half_size.array() <= 0.0).any()) {
      throw std::invalid_argument("BoxWorld: every box needs a finite centre and positive size");
    }
    if (!(b.rotation * b.rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6)) {
      throw std::invalid_argument("BoxWorld: box rotation must be orthonormal");
    }
  }
  axis_aligned_.reserve(boxes_.size());
  for (const Box& b : boxes_) axis_aligned_.push_back(b.rotation == Eigen::Matrix3d::Identity());
  order_.resize(boxes_.size());
  std::iota(order_.begin(), order_.end(), 0);
  bounds_.setEmpty();
  for (const Box& b : boxes_) bounds_.extend(b.aabb());
  if (!boxes_.empty()) {
    nodes_.reserve(2 * boxes_.size());
    build(0, static_cast<int>(boxes_.size()));
  }
}

int BoxWorld::build(int first, int count) {
  Node node;
  node.box.setEmpty();
  for (int i = first; i < first + count; ++i) node.box.extend(boxes_[order_[i]].aabb());
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(node);
  if (count <= 4) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  node.box.sizes().maxCoeff(&axis);
  const int mid = first + count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) { return boxes_[a].center[axis] < boxes_[b].center[axis]; });
  const int left = build(first, mid - first);
  const int right = build(mid, first + count - mid);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

double BoxWorld::intersect(int box, const Eigen::Vector3d& origin,
                           const Eigen::Vector3d& direction, const Eigen::Vector3d& inv_direction,
                           double t_max) const {
  const Box& b = boxes_[box];
  const Eigen::AlignedBox3d local(-b.half_size, b.half_size);
  if (axis_aligned_[box]) return ray_aabb(origin - b.center, inv_direction, local, t_max);
  const Eigen::Vector3d o = b.rotation.transpose() * (origin - b.center);
  const Eigen::Vector3d d = b.rotation.transpose() * direction;
  return ray_aabb(o, d.cwiseInverse(), local, t_max);
}

double BoxWorld::cast_among(const int* candidates, std::size_t count,
                           const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                           const Eigen::Vector3d& inv_direction, double max_range) const {
  double best = max_range;
  for (std::size_t i = 0; i < count; ++i) {
    best = std::min(best, intersect(candidates[i], origin, direction, inv_direction, best));
  }
  return best;
}

double BoxWorld::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                      double max_range) const {
  if (!origin.allFinite() || !direction.allFinite() || std::abs(direction.norm() - 1.0) > 1e-6) {
    throw std::invalid_argument("BoxWorld::cast: origin must be finite and direction a unit vector");
  }
  if (nodes_.empty()) return max_range;
  const Eigen::Vector3d inv_d = direction.cwiseInverse();
  double best = max_range;
  // (node, entry distance) pairs; the depth of a median-split tree of 2^31 boxes is 31, and
  // each level pushes at most two
  std::pair<int, double> stack[128];
  int top = 0;
  const double t_root = ray_aabb(origin, inv_d, nodes_[0].box, best);
  if (t_root < best) stack[top++] = {0, t_root};
  while (top > 0) {
    const auto [index, entry] = stack[--top];
    if (entry >= best) continue;  // a nearer hit was found after this node was pushed
    const Node& node = nodes_[index];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        // a box entered before best gives Box::intersect's value; one entered beyond it
        // gives +inf (ray_aabb's t_max), which changes no minimum
        best = std::min(best, intersect(order_[i], origin, direction, inv_d, best));
      }
      continue;
    }
    const double t_left = ray_aabb(origin, inv_d, nodes_[node.left].box, best);
    const double t_right = ray_aabb(origin, inv_d, nodes_[node.right].box, best);
    // the farther child below the nearer one, so the nearer is visited first
    const bool left_first = t_left <= t_right;
    const std::pair<int, double> near{left_first ? node.left : node.right,
                                      left_first ? t_left : t_right};
    const std::pair<int, double> far{left_first ? node.right : node.left,
                                     left_first ? t_right : t_left};
    if (far.second < best) stack[top++] = far;
    if (near.second < best) stack[top++] = near;
  }
  return best;
}

template <typename Visit>
void BoxWorld::query(const Eigen::AlignedBox3d& region, Visit&& visit) const {
  if (nodes_.empty()) return;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!node.box.intersects(region)) continue;
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        if (visit(boxes_[order_[i]])) return;
      }
    } else {
      stack[top++] = node.left;
      stack[top++] = node.right;
    }
  }
}

bool BoxWorld::occupied(const Eigen::Vector3d& p) const {
  bool inside = false;
  query(Eigen::AlignedBox3d(p, p), [&](const Box& b) { return inside = b.contains(p); });
  return inside;
}

void BoxWorld::rasterize_band(double z_min, double z_max, OccupancyGrid& grid) const {
  if (!(z_max > z_min)) throw std::invalid_argument("rasterize_band: need z_max > z_min");
  const double res = grid.resolution();
  const int steps_xy = 2, steps_z = std::max(1, static_cast<int>(std::ceil((z_max - z_min) / (0.5 * res))));
  for (int cy = 0; cy < grid.height(); ++cy) {
    auto* row = grid.cells().ptr<std::int8_t>(cy);
    for (int cx = 0; cx < grid.width(); ++cx) {
      const Eigen::Vector2d lo = grid.grid_to_world({cx + 0.0, cy + 0.0});
      const Eigen::Vector2d hi = grid.grid_to_world({cx + 1.0, cy + 1.0});
      const Eigen::AlignedBox3d column(Eigen::Vector3d(std::min(lo.x(), hi.x()), std::min(lo.y(), hi.y()), z_min),
                                       Eigen::Vector3d(std::max(lo.x(), hi.x()), std::max(lo.y(), hi.y()), z_max));
      bool hit = false;
      query(column, [&](const Box& b) {
        for (int iy = 0; iy < steps_xy && !hit; ++iy)
          for (int ix = 0; ix < steps_xy && !hit; ++ix) {
            const Eigen::Vector2d xy = grid.grid_to_world({cx + (ix + 0.5) / steps_xy, cy + (iy + 0.5) / steps_xy});
            for (int iz = 0; iz <= steps_z && !hit; ++iz) {
              hit = b.contains({xy.x(), xy.y(), z_min + (z_max - z_min) * iz / steps_z});
            }
          }
        return hit;
      });
      row[cx] = hit ? kOccupied : kFree;
    }
  }
}

}  // namespace kiseki
