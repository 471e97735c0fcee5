// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/kld_sampling.hpp"

#include <cmath>
#include <stdexcept>

namespace kiseki {

namespace {
// err: the KL bound epsilon (nav2's pf_err 0.01-0.05; above 1 any cloud passes); z: the upper
// standard normal quantile (nav2's pf_z 0.99; 10 is 1 - 1e-23)
void check_err_z(double err, double z) {
  if (!(err > 0.0 && err <= 1.0) || !(z >= 0.0 && z <= 10.0)) {
    throw std::invalid_argument("KLD sampling: err must lie in (0, 1] and z in [0, 10]");
  }
}

// Fox's eq. 14 for err and z already checked.
std::size_t sample_bound(std::size_t bins, double err, double z) {
  if (bins <= 1) return 0;
  const double k1 = static_cast<double>(bins - 1);
  const double a = 2.0 / (9.0 * k1);
  const double b = 1.0 - a + std::sqrt(a) * z;
  return static_cast<std::size_t>(std::ceil(k1 / (2.0 * err) * b * b * b));
}
}  // namespace

std::size_t kld_sample_bound(std::size_t bins, double err, double z) {
  check_err_z(err, z);
  return sample_bound(bins, err, z);
}

KldBins::KldBins(const KldParams& params) : params_(params) { check_err_z(params.err, params.z); }

void KldParams::validate() const {
  check_err_z(err, z);
  if (!(bin_xy > 0.0) || !(bin_theta > 0.0) || !(bin_distance > 0.0) || !std::isfinite(bin_xy + bin_theta + bin_distance)) {
    throw std::invalid_argument("KLD sampling: bin sizes must be finite and > 0");
  }
  if (min_particles < 1 || max_particles < min_particles || max_particles > 10'000'000) {
    throw std::invalid_argument("KLD sampling: need 1 <= min_particles <= max_particles <= 10,000,000");
  }
}

namespace {
std::uint64_t key_of(std::int64_t a, std::int64_t b, std::int64_t c) {
  // 21 bits per index: enough for 1 million bins per axis around the origin.
  const auto f = [](std::int64_t v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
  return (f(a) << 42) | (f(b) << 21) | f(c);
}
}  // namespace

bool KldBins::add(const Pose2& p) {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x / params_.bin_xy));
  const auto iy = static_cast<std::int64_t>(std::floor(p.y / params_.bin_xy));
  const auto it = static_cast<std::int64_t>(std::floor(p.theta / params_.bin_theta));
  return bins_.insert(key_of(ix, iy, it)).second;
}

bool KldBins::add(double s) {
  return bins_.insert(key_of(static_cast<std::int64_t>(std::floor(s / params_.bin_distance)), 0, 0)).second;
}

bool KldBins::enough(std::size_t n) const {
  if (n < params_.min_particles) return false;
  if (n >= params_.max_particles) return true;
  return n >= sample_bound(bins_.size(), params_.err, params_.z);  // checked by the constructor
}

}  // namespace kiseki
