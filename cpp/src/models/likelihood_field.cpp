// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/likelihood_field.hpp"

#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/grid/distance_field.hpp"

namespace kiseki {

void LikelihoodFieldParams::validate() const {
  if (!(sigma_hit > 0.0) || !(z_hit >= 0.0) || !(z_rand >= 0.0) || !(z_hit + z_rand > 0.0) ||
      beam_stride < 1) {
    throw std::invalid_argument("likelihood field: need sigma_hit > 0, z >= 0, beam_stride >= 1");
  }
}

LikelihoodFieldModel::LikelihoodFieldModel(const OccupancyGrid& map,
                                           const LikelihoodFieldParams& params)
    : params_((params.validate(), params)), frame_(map.clone()), distance_(distance_field(map)) {}

void LikelihoodFieldModel::set_scan(const double* angles, const float* ranges, std::size_t n,
                                    double max_range) {
  if (!(max_range > 0.0)) throw std::invalid_argument("likelihood field: max_range must be > 0");
  cos_.clear(), sin_.clear(), range_.clear();
  for (std::size_t i = 0; i < n; i += static_cast<std::size_t>(params_.beam_stride)) {
    if (!std::isfinite(ranges[i]) || ranges[i] <= 0.0f || ranges[i] >= max_range) continue;
    cos_.push_back(std::cos(angles[i]));
    sin_.push_back(std::sin(angles[i]));
    range_.push_back(ranges[i]);
  }
  max_range_ = max_range;
}

void LikelihoodFieldModel::log_likelihoods(const double* poses, std::size_t n, double* out) const {
  const double inv2s2 = 1.0 / (2.0 * params_.sigma_hit * params_.sigma_hit);
  const double norm = params_.z_hit / (std::sqrt(2.0 * kPi) * params_.sigma_hit);
  const double rand = params_.z_rand / max_range_;
  const float far = static_cast<float>(3.0 * params_.sigma_hit + 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double x = poses[3 * k], y = poses[3 * k + 1], th = poses[3 * k + 2];
    const double c = std::cos(th), s = std::sin(th);
    double log_l = 0.0;
    for (std::size_t b = 0; b < range_.size(); ++b) {
      const double bc = c * cos_[b] - s * sin_[b], bs = s * cos_[b] + c * sin_[b];
      const Eigen::Vector2d g = frame_.world_to_grid({x + range_[b] * bc, y + range_[b] * bs});
      const int cx = static_cast<int>(std::floor(g.x())), cy = static_cast<int>(std::floor(g.y()));
      const float d = frame_.contains(cx, cy) ? distance_.ptr<float>(cy)[cx] : far;
      log_l += std::log(norm * std::exp(-d * d * inv2s2) + rand);
    }
    out[k] = log_l;
  }
}

}  // namespace kiseki
