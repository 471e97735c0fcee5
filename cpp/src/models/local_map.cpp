// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/local_map.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "kiseki/grid/ray_casting.hpp"

namespace kiseki {
namespace {

constexpr std::uint8_t kHit = 1, kPassed = 2, kShadow = 4;

int cells_of(const LocalMapParams& p) { return static_cast<int>(std::lround(p.size / p.resolution)); }

}  // namespace

void LocalMapParams::validate() const {
  if (!(resolution > 0.0) || !(size >= resolution) || !std::isfinite(size) ||
      size / resolution > 4096) {
    throw std::invalid_argument("local map: need 0 < resolution <= size, at most 4096 cells a side");
  }
}

LocalMapBuilder::LocalMapBuilder(const LocalMapParams& params)
    : params_((params.validate(), params)),
      frame_(cells_of(params), cells_of(params), params.resolution,
             Pose2(-0.5 * cells_of(params) * params.resolution,
                   -0.5 * cells_of(params) * params.resolution, 0.0),
             kFree),
      flags_(static_cast<std::size_t>(frame_.width()) * frame_.height(), 0) {}

void LocalMapBuilder::mark(const CellIndex& c, std::uint8_t flag) {
  flags_[static_cast<std::size_t>(c.y) * frame_.width() + c.x] |= flag;
}

void LocalMapBuilder::add_scan(const Pose2& sensor, const double* angles, const float* ranges,
                               std::size_t n, double max_range) {
  if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || !std::isfinite(sensor.theta) ||
      !(max_range > 0.0) || !std::isfinite(max_range)) {
    throw std::invalid_argument("local map: sensor pose and max_range must be finite");
  }
  RayCastOptions through;  // an empty frame: walk every cell to the edge of L
  through.occupied_threshold = std::numeric_limits<std::int8_t>::max();
  through.max_range = 2.0 * params_.size;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = ranges[i];
    if (!std::isfinite(r) || r < 0.0 || !std::isfinite(angles[i])) continue;
    const bool hit = r < max_range;
    const double heading = sensor.theta + angles[i];
    const Eigen::Vector2d start(sensor.x, sensor.y);
    const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
    // The cell holding the beam's end is the hit (as in map building); the cells the beam
    // crosses before it are free; the cells after it along the ray are hidden (occupied).
    const CellIndex end = frame_.world_to_cell(start + std::min(r, 2.0 * params_.size) * dir);
    bool behind = false;
    for (const CellIndex& c : cells_on_ray(frame_, start, heading, through)) {
      if (!hit) {
        const Eigen::Vector2d centre = frame_.cell_to_world(c.x, c.y);
        if ((centre - start).dot(dir) > max_range) break;
        mark(c, kPassed);
      } else if (c == end) {
        mark(c, kHit);
        behind = true;
      } else {
        mark(c, behind ? kShadow : kPassed);
      }
    }
  }
}

void LocalMapBuilder::add_depth_band(const cv::Mat& depth, const PinholeCamera& cam,
                                     const Pose3& optical_in_robot, double z_min, double z_max) {
  cam.validate();
  if (depth.type() != CV_32FC1 || depth.rows != cam.height || depth.cols != cam.width) {
    throw std::invalid_argument("local map: the depth image must be float32 of the camera's size (" +
                                std::to_string(cam.width) + " x " + std::to_string(cam.height) + ")");
  }
  if (!(z_max > z_min)) throw std::invalid_argument("local map: need z_max > z_min");
  const Eigen::Matrix3d r = optical_in_robot.rotation.toRotationMatrix();
  const Eigen::Vector3d t = optical_in_robot.translation;
  const Pose2 sensor(t.x(), t.y(), 0.0);
  std::vector<double> angles(static_cast<std::size_t>(cam.width));
  std::vector<float> ranges(angles.size());
  for (int u = 0; u < cam.width; ++u) {
    // The column's heading in the robot frame: its optical ray at the principal row.
    const Eigen::Vector3d axis = r * Eigen::Vector3d((u + 0.5 - cam.cx) / cam.fx, 0.0, 1.0);
    angles[u] = std::atan2(axis.y(), axis.x());
    double nearest = std::numeric_limits<double>::infinity();
    for (int v = 0; v < cam.height; ++v) {
      const float z = depth.ptr<float>(v)[u];
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      const Eigen::Vector3d p = r * Eigen::Vector3d((u + 0.5 - cam.cx) / cam.fx * z,
                                                    (v + 0.5 - cam.cy) / cam.fy * z, z) + t;
      if (p.z() < z_min || p.z() > z_max) continue;
      nearest = std::min(nearest, std::hypot(p.x() - t.x(), p.y() - t.y()));
    }
    ranges[u] = std::isfinite(nearest) ? static_cast<float>(nearest)
                                       : static_cast<float>(cam.max_range);
  }
  add_scan(sensor, angles.data(), ranges.data(), angles.size(), cam.max_range);
}

OccupancyGrid LocalMapBuilder::build() const {
  OccupancyGrid out = frame_.clone();
  for (int y = 0; y < out.height(); ++y) {
    auto* row = out.cells().ptr<std::int8_t>(y);
    for (int x = 0; x < out.width(); ++x) {
      const std::uint8_t f = flags_[static_cast<std::size_t>(y) * out.width() + x];
      row[x] = (f & kHit) ? kOccupied : (f & kPassed) ? kFree : (f & kShadow) ? kOccupied : kUnknown;
    }
  }
  return out;
}

}  // namespace kiseki
