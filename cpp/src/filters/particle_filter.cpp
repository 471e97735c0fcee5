// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/particle_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "kiseki/core/angle.hpp"

namespace kiseki {

void ParticleFilterParams::validate() const {
  if (particles < 1 || particles > 10'000'000) {
    throw std::invalid_argument("particle filter: particles must be in 1..10,000,000");
  }
  for (double a : {alpha1, alpha2, alpha3, alpha4}) {
    if (!(a >= 0.0) || !std::isfinite(a)) throw std::invalid_argument("particle filter: alphas must be >= 0");
  }
  if (!(resample_threshold >= 0.0 && resample_threshold <= 1.0)) {
    throw std::invalid_argument("particle filter: resample_threshold must lie in [0, 1]");
  }
}

ParticleFilter::ParticleFilter(const ParticleFilterParams& params, std::uint64_t seed)
    : params_((params.validate(), params)), rng_(seed) {}

void ParticleFilter::initialize(const Pose2& mean, double sd_x, double sd_y, double sd_theta) {
  if (!(sd_x >= 0.0) || !(sd_y >= 0.0) || !(sd_theta >= 0.0)) {
    throw std::invalid_argument("particle filter: standard deviations must be >= 0");
  }
  std::vector<Pose2> p(static_cast<std::size_t>(params_.particles));
  for (auto& q : p) {
    q = Pose2(rng_.normal(mean.x, sd_x), rng_.normal(mean.y, sd_y), rng_.normal(mean.theta, sd_theta));
  }
  set_particles(p);
}

void ParticleFilter::set_particles(const std::vector<Pose2>& particles) {
  if (particles.empty()) throw std::invalid_argument("particle filter: no particles");
  for (const auto& q : particles) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.theta)) {
      throw std::invalid_argument("particle filter: particles must be finite");
    }
  }
  particles_ = particles;
  weights_.assign(particles_.size(), 1.0 / particles_.size());
}

namespace {
constexpr double kTurnOnTheSpot = 0.01;  // m
}  // namespace

void ParticleFilter::predict(const Pose2& a, const Pose2& b) {
  // Probabilistic Robotics, Table 5.6: decompose the odometry increment.
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double trans = std::hypot(dx, dy);
  // Below kTurnOnTheSpot the increment is a turn on the spot (ROS AMCL's rule): the direction
  // of a millimetre of wheel slip says nothing, and taking it for rot1 (anything up to pi)
  // would spread the heading as if the robot had turned twice as far.
  const double rot1 =
      trans < kTurnOnTheSpot ? 0.0 : angle_difference(std::atan2(dy, dx), a.theta);
  const double rot2 = angle_difference(angle_difference(b.theta, a.theta), rot1);
  // Reversing is not turning: the noise of a backward move is that of a forward one, so the
  // rotations enter the noise folded to [0, pi/2] (rot1 = pi means straight back).
  const auto folded = [](double r) { return std::min(std::abs(r), kPi - std::abs(r)); };
  const double n1 = folded(rot1), n2 = folded(rot2);
  const auto& p = params_;
  const double sd_rot1 = std::sqrt(p.alpha1 * n1 * n1 + p.alpha2 * trans * trans);
  const double sd_trans = std::sqrt(p.alpha3 * trans * trans + p.alpha4 * (n1 * n1 + n2 * n2));
  const double sd_rot2 = std::sqrt(p.alpha1 * n2 * n2 + p.alpha2 * trans * trans);
  for (auto& q : particles_) {
    const double r1 = rot1 - rng_.normal(0.0, sd_rot1);
    const double t = trans - rng_.normal(0.0, sd_trans);
    const double r2 = rot2 - rng_.normal(0.0, sd_rot2);
    q = Pose2(q.x + t * std::cos(q.theta + r1), q.y + t * std::sin(q.theta + r1), q.theta + r1 + r2);
  }
}

bool ParticleFilter::weight(const std::vector<double>& likelihoods) {
  if (likelihoods.size() != particles_.size()) {
    throw std::invalid_argument("particle filter: one likelihood per particle is needed");
  }
  double total = 0.0;
  for (std::size_t i = 0; i < weights_.size(); ++i) {
    if (!(likelihoods[i] >= 0.0) || !std::isfinite(likelihoods[i])) {
      throw std::invalid_argument("particle filter: likelihoods must be finite and >= 0");
    }
    weights_[i] *= likelihoods[i];
    total += weights_[i];
  }
  if (!(total > 0.0)) {
    weights_.assign(weights_.size(), 1.0 / weights_.size());
    return false;
  }
  for (double& w : weights_) w /= total;
  return true;
}

double ParticleFilter::effective_sample_size() const {
  double s = 0.0;
  for (double w : weights_) s += w * w;
  return s > 0.0 ? 1.0 / s : 0.0;
}

bool ParticleFilter::resample_if_needed() {
  if (effective_sample_size() >= params_.resample_threshold * particles_.size()) return false;
  resample();
  return true;
}

void ParticleFilter::resample() {
  // Low-variance (systematic) resampling, Probabilistic Robotics Table 4.4.
  const std::size_t n = particles_.size();
  std::vector<Pose2> out(n);
  const double step = 1.0 / n;
  double u = rng_.uniform(0.0, step), c = weights_[0];
  std::size_t i = 0;
  for (std::size_t m = 0; m < n; ++m) {
    while (u > c && i + 1 < n) c += weights_[++i];
    out[m] = particles_[i];
    u += step;
  }
  particles_.swap(out);
  weights_.assign(n, step);
}

Pose2 ParticleFilter::estimate() const {
  if (particles_.empty()) throw std::logic_error("particle filter: not initialised");
  double x = 0, y = 0, c = 0, s = 0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double w = weights_[i];
    x += w * particles_[i].x;
    y += w * particles_[i].y;
    c += w * std::cos(particles_[i].theta);
    s += w * std::sin(particles_[i].theta);
  }
  return {x, y, std::atan2(s, c)};
}

}  // namespace kiseki
