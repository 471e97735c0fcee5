// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/beam_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "kiseki/core/angle.hpp"

namespace kiseki {

void BeamModelParams::validate() const {
  for (double z : {z_hit, z_short, z_max, z_rand}) {
    if (!(z >= 0.0) || !std::isfinite(z)) throw std::invalid_argument("beam model: z weights must be finite and >= 0");
  }
  if (!(z_hit + z_short + z_max + z_rand > 0.0)) throw std::invalid_argument("beam model: the z weights are all 0");
  if (!(sigma_hit > 0.0) || !std::isfinite(sigma_hit)) throw std::invalid_argument("beam model: sigma_hit must be > 0");
  // a micrometre at least: 1e-300 squared is 0, and the Gaussian 0 / 0 (NaN log-likelihoods)
  if (sigma_hit < kMinSigmaHit) throw std::invalid_argument("beam model: sigma_hit must be at least 1e-6 m");
  if (!(lambda_short > 0.0) || !std::isfinite(lambda_short)) {
    throw std::invalid_argument("beam model: lambda_short must be > 0");
  }
  if (max_beams < 0) throw std::invalid_argument("beam model: max_beams must be >= 0");
  if (!(agreement_tolerance >= 0.0) || !std::isfinite(agreement_tolerance)) {
    throw std::invalid_argument("beam model: agreement_tolerance must be >= 0");
  }
}

BeamModel::BeamModel(const OccupancyGrid& map, const BeamModelParams& params)
    : params_((params.validate(), params)), occupied_(map, /*unknown_stops=*/false) {
  // 64 sectors of one byte a cell (SectorCaster's default): past the limit, the distance field
  const std::size_t table = static_cast<std::size_t>(map.width()) * static_cast<std::size_t>(map.height()) * 64;
  if (params.caster == RayCasterKind::swept_sector && table <= kMaxSectorTableBytes) {
    sector_.emplace(map, params.unknown_stops);
  } else {
    field_.emplace(map, params.unknown_stops);
  }
}

void BeamModel::expected_ranges(const Pose2& sensor, const double* reach, double* z_star) const {
  const std::size_t m = beams_.size();
  if (sector_) {
    sector_->scan(sensor, beams_.cos.data(), beams_.sin.data(), reach, m, z_star);
    return;
  }
  for (std::size_t b = 0; b < m; ++b) {
    z_star[b] = field_->range(sensor.x, sensor.y, sensor.theta + beams_.angle[b], reach[b]);
  }
}

void BeamModel::set_scan(const double* angles, const float* ranges, std::size_t n, double max_range) {
  beams_.set(angles, ranges, n, max_range, params_.max_beams, /*keep_no_return=*/true);
  // The terms of pz that depend on the reading only, once a scan (as beam_probability has them).
  const auto& p = params_;
  short_term_.resize(beams_.size());
  floor_term_.resize(beams_.size());
  for (std::size_t b = 0; b < beams_.size(); ++b) {
    short_term_[b] = p.z_short * p.lambda_short * std::exp(-p.lambda_short * beams_.range[b]);
    floor_term_[b] = beams_.no_return[b] ? p.z_max : p.z_rand / beams_.max_range;
  }
  has_scan_ = true;
}

double BeamModel::beam_probability(double z, double z_star, bool no_return) const {
  const auto& p = params_;
  const double e = z - z_star;
  double g = std::exp(-e * e / (2.0 * p.sigma_hit * p.sigma_hit));
  if (p.combination == BeamCombination::product) g /= std::sqrt(2.0 * kPi) * p.sigma_hit;
  double pz = p.z_hit * g;
  if (e < 0.0) pz += p.z_short * p.lambda_short * std::exp(-p.lambda_short * z);
  if (no_return) pz += p.z_max;
  else pz += p.z_rand / beams_.max_range;
  return pz;
}

void BeamModel::log_likelihoods(const Pose2* poses, std::size_t n, double* out) const {
  if (!has_scan_) throw std::logic_error("beam model: set a scan first");
  const std::size_t m = beams_.size();
  const bool nav2 = params_.combination == BeamCombination::nav2;
  // Past reading + 8 sigma the Gaussian term is below exp(-32) of its peak, and every longer z*
  // scores the same (the short term only asks z < z*): the ray stops there.
  std::vector<double> reach(m), z_star(m);
  for (std::size_t b = 0; b < m; ++b) {
    reach[b] = beams_.no_return[b] ? beams_.max_range
                                   : std::min(beams_.max_range, beams_.range[b] + 8.0 * params_.sigma_hit);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Pose2 s = poses[k].compose(params_.sensor);
    expected_ranges(s, reach.data(), z_star.data());
    double sum = 0.0;
    for (std::size_t b = 0; b < m; ++b) {  // beam_probability, its reading's terms from set_scan
      const double e = beams_.range[b] - z_star[b];
      double g = std::exp(-e * e / (2.0 * params_.sigma_hit * params_.sigma_hit));
      if (!nav2) g /= std::sqrt(2.0 * kPi) * params_.sigma_hit;
      double pz = params_.z_hit * g;
      if (e < 0.0) pz += short_term_[b];
      pz += floor_term_[b];
      sum += nav2 ? pz * pz * pz : std::log(pz);
    }
    out[k] = nav2 ? std::log1p(sum) : sum;
  }
}

double BeamModel::agreement(const Pose2& pose) const {
  return beams_.agreement(occupied_, pose.compose(params_.sensor), params_.agreement_tolerance);
}

}  // namespace kiseki
