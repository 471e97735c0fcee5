// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/mapping/log_odds_mapper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "kiseki/grid/ray_casting.hpp"

namespace kiseki {
namespace {

float logit(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }

bool usable(float r, const LogOddsParams& p) { return std::isfinite(r) && r > p.min_range; }

// Whether a reading marks free space along its beam.
bool clears(float r, const LogOddsParams& p) {
  return usable(r, p) && (r < p.max_range || p.clear_on_no_return);
}

int checked_cells(double extent, double resolution) {
  const double n = std::ceil(extent / resolution);
  if (!(n >= 1.0) || n > 200000.0) {
    throw std::invalid_argument("LogOddsMapper: map extent gives an unreasonable cell count");
  }
  return static_cast<int>(n);
}

}  // namespace

void validate(const LogOddsParams& p) {
  const auto prob = [](double v) { return std::isfinite(v) && v > 0.0 && v < 1.0; };
  if (!(p.resolution > 0.0) || !std::isfinite(p.resolution)) {
    throw std::invalid_argument("log-odds mapping: resolution must be positive");
  }
  if (!(p.max_range > 0.0) || !(p.usable_range > 0.0) || !(p.min_range >= 0.0) ||
      !std::isfinite(p.max_range) || !std::isfinite(p.usable_range)) {
    throw std::invalid_argument("log-odds mapping: ranges must be positive and finite");
  }
  if (!prob(p.prob_hit) || !prob(p.prob_miss) || !prob(p.clamp_min) || !prob(p.clamp_max) ||
      p.prob_hit <= 0.5 || p.prob_miss >= 0.5 || p.clamp_min >= p.clamp_max) {
    throw std::invalid_argument(
        "log-odds mapping: need 0 < prob_miss < 0.5 < prob_hit < 1 and clamp_min < clamp_max");
  }
  if (p.free_thresh > p.occupied_thresh) {
    throw std::invalid_argument("log-odds mapping: free_thresh must not exceed occupied_thresh");
  }
}

LogOddsMapper::LogOddsMapper(double min_x, double min_y, double max_x, double max_y,
                             const LogOddsParams& params)
    : params_((validate(params), params)),
      frame_(checked_cells(max_x - min_x, params.resolution),
             checked_cells(max_y - min_y, params.resolution), params.resolution,
             Pose2(min_x, min_y, 0.0)),
      l_hit_(logit(params.prob_hit)),
      l_miss_(logit(params.prob_miss)),
      l_min_(logit(params.clamp_min)),
      l_max_(logit(params.clamp_max)) {
  log_odds_ = cv::Mat(frame_.height(), frame_.width(), CV_32FC1, cv::Scalar(0.0f));
  hit_stamp_.assign(static_cast<std::size_t>(frame_.width()) * frame_.height(), 0);
  miss_stamp_ = hit_stamp_;
}

void LogOddsMapper::integrate_scan(const Pose2& pose, const float* ranges, const double* angles,
                                   std::size_t n) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    throw std::invalid_argument("LogOddsMapper: sensor pose must be finite");
  }
  const std::uint32_t stamp = ++scans_;
  const int w = frame_.width();
  float* l = log_odds_.ptr<float>(0);
  hit_cells_.clear();
  for (std::size_t i = 0; i < n; ++i) {  // pass 1: end cells of returns
    if (!usable(ranges[i], params_) || ranges[i] >= params_.max_range) continue;
    const double a = pose.theta + angles[i];
    const CellIndex c = frame_.world_to_cell(
        {pose.x + ranges[i] * std::cos(a), pose.y + ranges[i] * std::sin(a)});
    if (!frame_.contains(c)) continue;
    const int idx = c.y * w + c.x;
    if (hit_stamp_[idx] != stamp) {
      hit_stamp_[idx] = stamp;
      hit_cells_.push_back(idx);
    }
  }
  RayCastOptions free_space;
  free_space.occupied_threshold = std::numeric_limits<std::int8_t>::max();  // never stop
  for (std::size_t i = 0; i < n; ++i) {  // pass 2: free space along the beams
    if (!clears(ranges[i], params_)) continue;
    free_space.max_range = std::min<double>(ranges[i], params_.usable_range);
    for (const CellIndex& c : cells_on_ray(frame_, {pose.x, pose.y}, pose.theta + angles[i],
                                           free_space)) {
      const int idx = c.y * w + c.x;
      if (hit_stamp_[idx] == stamp || miss_stamp_[idx] == stamp) continue;
      miss_stamp_[idx] = stamp;
      l[idx] = std::max(l_min_, l[idx] + l_miss_);
    }
  }
  for (int idx : hit_cells_) l[idx] = std::min(l_max_, l[idx] + l_hit_);
}

OccupancyGrid LogOddsMapper::to_occupancy() const {
  OccupancyGrid grid(frame_.width(), frame_.height(), frame_.resolution(), frame_.origin(),
                     kUnknown);
  const float occ = logit(params_.occupied_thresh), fr = logit(params_.free_thresh);
  for (int y = 0; y < grid.height(); ++y) {
    const float* l = log_odds_.ptr<float>(y);
    auto* out = grid.cells().ptr<std::int8_t>(y);
    for (int x = 0; x < grid.width(); ++x) {
      if (l[x] > occ) out[x] = kOccupied;
      else if (l[x] < fr) out[x] = kFree;
    }
  }
  return grid;
}

std::vector<double> LogOddsMapper::scan_bounds(const double* poses, const float* ranges,
                                               const double* angles, std::size_t n_scans,
                                               std::size_t n_beams, const LogOddsParams& p) {
  validate(p);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> b = {inf, inf, -inf, -inf};
  const auto grow = [&b](double x, double y) {
    b[0] = std::min(b[0], x), b[1] = std::min(b[1], y);
    b[2] = std::max(b[2], x), b[3] = std::max(b[3], y);
  };
  for (std::size_t s = 0; s < n_scans; ++s) {
    const double x = poses[3 * s], y = poses[3 * s + 1], th = poses[3 * s + 2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(th)) {
      throw std::invalid_argument("scan_bounds: poses must be finite");
    }
    grow(x, y);
    for (std::size_t i = 0; i < n_beams; ++i) {
      const float r = ranges[s * n_beams + i];
      if (!usable(r, p) || (r >= p.max_range && !p.clear_on_no_return)) continue;
      const double d = r < p.max_range ? r : std::min<double>(r, p.usable_range);
      grow(x + d * std::cos(th + angles[i]), y + d * std::sin(th + angles[i]));
    }
  }
  if (n_scans == 0) throw std::invalid_argument("scan_bounds: no scans");
  return b;
}

std::pair<std::size_t, std::size_t> endpoint_agreement(
    const OccupancyGrid& grid, const double* poses, const float* ranges, const double* angles,
    std::size_t n_scans, std::size_t n_beams, double max_range, int neighbourhood,
    std::int8_t occupied_threshold) {
  if (neighbourhood < 0 || neighbourhood > 10) {
    throw std::invalid_argument("endpoint_agreement: neighbourhood must be in 0..10");
  }
  std::size_t hits = 0, endpoints = 0;
  for (std::size_t s = 0; s < n_scans; ++s) {
    const double x = poses[3 * s], y = poses[3 * s + 1], th = poses[3 * s + 2];
    for (std::size_t i = 0; i < n_beams; ++i) {
      const float r = ranges[s * n_beams + i];
      if (!std::isfinite(r) || r <= 0.0f || r >= max_range) continue;
      ++endpoints;
      const CellIndex c =
          grid.world_to_cell({x + r * std::cos(th + angles[i]), y + r * std::sin(th + angles[i])});
      bool found = false;
      for (int dy = -neighbourhood; dy <= neighbourhood && !found; ++dy) {
        for (int dx = -neighbourhood; dx <= neighbourhood && !found; ++dx) {
          found = grid.contains(c.x + dx, c.y + dy) &&
                  grid.value(c.x + dx, c.y + dy) >= occupied_threshold;
        }
      }
      hits += found;
    }
  }
  return {hits, endpoints};
}

}  // namespace kiseki
