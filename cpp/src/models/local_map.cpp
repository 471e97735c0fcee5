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

void LocalMapBuilder::add_beam(const Eigen::Vector2d& start, double heading, double free_from,
                               double range, bool hit) {
  RayCastOptions through;  // an empty frame: walk every cell to the edge of L
  through.occupied_threshold = std::numeric_limits<std::int8_t>::max();
  through.max_range = 2.0 * params_.size;
  const Eigen::Vector2d dir(std::cos(heading), std::sin(heading));
  // The cell holding the beam's end is the hit (as in map building); the cells the beam
  // crosses before it are free; the cells after it along the ray are hidden (occupied).
  const CellIndex end =
      hit ? frame_.world_to_cell(start + std::min(range, 2.0 * params_.size) * dir) : CellIndex{-1, -1};
  bool behind = false;
  for (const CellIndex& c : cells_on_ray(frame_, start, heading, through)) {
    if (hit && c == end) {
      mark(c, kHit);
      behind = true;
      continue;
    }
    if (behind) {
      mark(c, kShadow);
      continue;
    }
    const double along = (frame_.cell_to_world(c.x, c.y) - start).dot(dir);
    if (!hit && along > range) break;
    if (free_from <= 0.0 || along >= free_from) mark(c, kPassed);
  }
}

void LocalMapBuilder::add_scan(const Pose2& sensor, const double* angles, const float* ranges,
                               std::size_t n, double max_range) {
  if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || !std::isfinite(sensor.theta) ||
      !(max_range > 0.0) || !std::isfinite(max_range)) {
    throw std::invalid_argument("local map: sensor pose and max_range must be finite");
  }
  const Eigen::Vector2d start(sensor.x, sensor.y);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = ranges[i];
    // No reading is no information: NaN, infinite, zero and negative ranges add nothing.
    if (!std::isfinite(r) || !(r > 0.0) || !std::isfinite(angles[i])) continue;
    const bool hit = r < max_range;
    add_beam(start, sensor.theta + angles[i], 0.0, hit ? r : max_range, hit);
  }
}

namespace {

// The values of f in [0, 1] with c0 + f * c1 <= bound, as [lo, hi] (lo > hi when none).
void clip_linear_le(double c0, double c1, double bound, double& lo, double& hi) {
  if (c1 == 0.0) {
    if (c0 > bound) lo = 2.0, hi = -1.0;
  } else if (c1 > 0.0) {
    hi = std::min(hi, (bound - c0) / c1);
  } else {
    lo = std::max(lo, (bound - c0) / c1);
  }
}

}  // namespace

void LocalMapBuilder::add_depth_band(const cv::Mat& depth, const PinholeCamera& cam,
                                     const Pose3& optical_in_robot, double z_min, double z_max) {
  cam.validate();
  if (depth.type() != CV_32FC1 || depth.rows != cam.height || depth.cols != cam.width) {
    throw std::invalid_argument("local map: the depth image must be float32 of the camera's size (" +
                                std::to_string(cam.width) + " x " + std::to_string(cam.height) + ")");
  }
  if (!std::isfinite(z_min) || !std::isfinite(z_max) || !(z_max >= z_min)) {
    throw std::invalid_argument("local map: need finite z_min <= z_max");
  }
  const Eigen::Matrix3d r = optical_in_robot.rotation.toRotationMatrix();
  const Eigen::Vector3d t = optical_in_robot.translation;
  if (!r.allFinite() || !t.allFinite()) {
    throw std::invalid_argument("local map: the camera pose must be finite");
  }
  const Eigen::Vector2d start(t.x(), t.y());
  // A pixel's ray for image coordinates (gx, gy) is r (gx, gy, 1): per column the part that
  // does not depend on the row is computed once, and a point at depth d is t + d * ray.
  std::vector<double> gy(static_cast<std::size_t>(cam.height) + 1);  // at row edges v = 0..H
  for (int v = 0; v <= cam.height; ++v) gy[v] = (v - cam.cy) / cam.fy;
  const Eigen::Vector3d down = r.col(1);
  for (int u = 0; u < cam.width; ++u) {
    // The column's heading in the robot frame: its optical ray at the principal row.
    const double gx = (u + 0.5 - cam.cx) / cam.fx;
    const Eigen::Vector3d base = r.col(0) * gx + r.col(2);
    const double heading = std::atan2(base.y(), base.x());
    double hit = std::numeric_limits<double>::infinity();  // nearest in-band reading
    double free_from = std::numeric_limits<double>::infinity(), free_to = 0.0;
    for (int v = 0; v < cam.height; ++v) {
      const float d = depth.ptr<float>(v)[u];
      // A reading is a depth within the camera's range; +inf is the camera's own "nothing
      // within range" (REP 117) and counts as a ray to max_range; 0, NaN, -inf and depths
      // outside the range are no reading and say nothing.
      const bool no_return = std::isinf(d) && d > 0.0f;
      if (!no_return && !(d >= cam.min_range && d < cam.max_range)) continue;
      const double z = no_return ? cam.max_range : static_cast<double>(d);
      const double centre = 0.5 * (gy[v] + gy[v + 1]);
      const double ax = base.x() + down.x() * centre, ay = base.y() + down.y() * centre;
      const double along = z * std::sqrt(ax * ax + ay * ay);  // horizontal distance
      // The pixel sees the band where its footprint (between its top and bottom edge rays)
      // overlaps [z_min, z_max]; at a fraction f of the way to the reading the footprint spans
      // t.z + f (z_edge - t.z), linear in f, so that part of the ray is an interval of f.
      const double top = z * (base.z() + down.z() * gy[v]);
      const double bottom = z * (base.z() + down.z() * gy[v + 1]);
      const double low = std::min(top, bottom), high = std::max(top, bottom);
      double f_lo = 0.0, f_hi = 1.0;
      clip_linear_le(t.z(), low, z_max, f_lo, f_hi);     // the lower edge below the top
      clip_linear_le(-t.z(), -high, -z_min, f_lo, f_hi);  // the upper edge above the bottom
      if (!(f_hi >= f_lo)) continue;                     // never in the band
      if (!no_return && f_hi >= 1.0) hit = std::min(hit, along);  // the reading is in the band
      free_from = std::min(free_from, f_lo * along);
      free_to = std::max(free_to, f_hi * along);
    }
    if (std::isfinite(hit)) {
      add_beam(start, heading, std::min(free_from, hit), hit, true);
    } else if (free_to > free_from) {
      add_beam(start, heading, free_from, free_to, false);  // free while in the band, no end
    }
  }
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

cv::Mat LocalMapBuilder::hits() const {
  cv::Mat out(frame_.height(), frame_.width(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < out.rows; ++y) {
    auto* row = out.ptr<std::uint8_t>(y);
    for (int x = 0; x < out.cols; ++x) {
      row[x] = (flags_[static_cast<std::size_t>(y) * out.cols + x] & kHit) ? 1 : 0;
    }
  }
  return out;
}

}  // namespace kiseki
