// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/ray_space_observation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/grid/distance_field.hpp"

namespace kiseki {

void RaySpaceObservationParams::validate() const {
  for (double z : {z_hit, z_rand, z_intrusion}) {
    if (!(z >= 0.0) || !std::isfinite(z)) {
      throw std::invalid_argument("ray space observation: z_hit, z_rand, z_intrusion must be finite and >= 0");
    }
  }
  if (!(z_rand > 0.0)) {
    throw std::invalid_argument("ray space observation: z_rand must be > 0 (every reading must be possible)");
  }
  if (sigma_hit < kMinSigmaHit) throw std::invalid_argument("ray space observation: sigma_hit must be at least 1e-6 m");
  for (double v : {sigma_hit, lambda_short, max_distance}) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      throw std::invalid_argument("ray space observation: sigma_hit, lambda_short, max_distance must be finite and > 0");
    }
  }
  if (max_beams < 0) throw std::invalid_argument("ray space observation: max_beams must be >= 0");
  if (!(agreement_tolerance >= 0.0) || !std::isfinite(agreement_tolerance)) {
    throw std::invalid_argument("ray space observation: agreement_tolerance must be >= 0");
  }
}

RaySpaceObservationModel::RaySpaceObservationModel(const OccupancyGrid& map,
                                                   const RaySpaceObservationParams& params)
    : params_((params.validate(), params)),
      frame_(map.clone()),
      distance_(cv::min(distance_field(map), params.max_distance)),
      occupied_(map, /*unknown_stops=*/false) {}

void RaySpaceObservationModel::set_scan(const double* angles, const float* ranges, std::size_t n,
                                        double max_range) {
  beams_.set(angles, ranges, n, max_range, params_.max_beams, /*keep_no_return=*/false);
  // The intrusion term depends on the reading only: once per beam, not per particle.
  intrusion_.resize(beams_.size());
  for (std::size_t b = 0; b < beams_.size(); ++b) {
    intrusion_[b] = params_.z_intrusion * params_.lambda_short * std::exp(-params_.lambda_short * beams_.range[b]);
  }
  has_scan_ = true;
}

double RaySpaceObservationModel::beam_probability(double r, double delta, double d) const {
  const auto& p = params_;
  const double h = std::max(d, delta);
  double pz = p.z_hit * std::exp(-h * h / (2.0 * p.sigma_hit * p.sigma_hit)) /
              (std::sqrt(2.0 * kPi) * p.sigma_hit);
  if (delta <= 0.0) pz += p.z_intrusion * p.lambda_short * std::exp(-p.lambda_short * r);
  return pz + p.z_rand / beams_.max_range;
}

void RaySpaceObservationModel::log_likelihoods(const Pose2* poses, std::size_t n, double* out) const {
  if (!has_scan_) throw std::logic_error("ray space observation: set a scan first");
  const std::size_t m = beams_.size();
  const Pose2 to_grid = frame_.origin().inverse();
  const double inv_res = 1.0 / frame_.resolution();
  const int w = frame_.width(), h = frame_.height();
  const float* dist = distance_.ptr<float>(0);  // continuous (cv::min allocates a new Mat)
  for (std::size_t k = 0; k < n; ++k) {
    const Pose2 s = poses[k].compose(params_.sensor);
    const Pose2 g = to_grid.compose(s);
    const double gc = std::cos(g.theta), gs = std::sin(g.theta);
    double sum = 0.0;
    for (std::size_t b = 0; b < m; ++b) {
      const double r = beams_.range[b];
      const double r_hat = occupied_.range(s.x, s.y, s.theta + beams_.angle[b], r);
      const double delta = std::max(0.0, r - r_hat);
      // The end in grid cells (as the likelihood field finds it).
      const double lx = r * beams_.cos[b], ly = r * beams_.sin[b];
      const double gx = (g.x + gc * lx - gs * ly) * inv_res, gy = (g.y + gs * lx + gc * ly) * inv_res;
      const bool inside = gx >= 0.0 && gy >= 0.0 && gx < w && gy < h;
      const double d = inside ? dist[static_cast<std::ptrdiff_t>(gy) * w + static_cast<std::ptrdiff_t>(gx)]
                              : params_.max_distance;
      // beam_probability(r, delta, d), with the beam's intrusion term computed once
      const double h = std::max(d, delta), sigma = params_.sigma_hit;
      double pz = params_.z_hit * std::exp(-h * h / (2.0 * sigma * sigma)) / (std::sqrt(2.0 * kPi) * sigma);
      if (delta <= 0.0) pz += intrusion_[b];
      sum += std::log(pz + params_.z_rand / beams_.max_range);
    }
    out[k] = sum;
  }
}

double RaySpaceObservationModel::placement_agreement(const Pose2& pose) const {
  return beams_.agreement(occupied_, pose.compose(params_.sensor), params_.agreement_tolerance);
}

double RaySpaceObservationModel::agreement(const Pose2& pose) const {
  return beams_.agreement(occupied_, pose.compose(params_.sensor), params_.agreement_tolerance,
                          params_.agreement_skips_intrusion);
}

}  // namespace kiseki
