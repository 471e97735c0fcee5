// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/motion_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/core/random.hpp"

namespace kiseki {

MotionModelType motion_model_from_name(const std::string& name) {
  if (name == "differential") return MotionModelType::differential;
  if (name == "omnidirectional") return MotionModelType::omnidirectional;
  throw std::invalid_argument("motion model: unknown type '" + name + "' (differential or omnidirectional)");
}

void MotionParams::validate() const {
  // at most 1,000: a noise SD about 30 times the motion itself (kiseki's noisy odometry, F < 10,
  // with a real odometry's alphas gives at most 100.05); 1e300 put the particles 1e148 m off
  for (double a : {alpha1, alpha2, alpha3, alpha4, alpha5}) {
    if (!(a >= 0.0 && a <= 1000.0)) throw std::invalid_argument("motion model: alphas must lie in [0, 1000]");
  }
}

namespace {
constexpr double kTurnOnTheSpot = 0.01;  // m
}  // namespace

void sample_motion(const MotionParams& p, const Pose2& a, const Pose2& b, Pose2* particles,
                   std::size_t n, std::uint64_t seed, int threads) {
  if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(a.theta) || !std::isfinite(b.x) ||
      !std::isfinite(b.y) || !std::isfinite(b.theta)) {
    throw std::invalid_argument("motion model: odometry poses must be finite");
  }
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double trans = std::hypot(dx, dy);
  if (p.type == MotionModelType::differential) {
    // Probabilistic Robotics, Table 5.6: decompose the increment into rot1, trans, rot2.
    const double rot1 = trans < kTurnOnTheSpot ? 0.0 : angle_difference(std::atan2(dy, dx), a.theta);
    const double rot2 = angle_difference(angle_difference(b.theta, a.theta), rot1);
    const auto folded = [](double r) { return std::min(std::abs(r), kPi - std::abs(r)); };
    const double n1 = folded(rot1), n2 = folded(rot2);
    const double sd_rot1 = std::sqrt(p.alpha1 * n1 * n1 + p.alpha2 * trans * trans);
    const double sd_trans = std::sqrt(p.alpha3 * trans * trans + p.alpha4 * (n1 * n1 + n2 * n2));
    const double sd_rot2 = std::sqrt(p.alpha1 * n2 * n2 + p.alpha2 * trans * trans);
    parallel_for(n, threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        StreamRandom rng(seed, i);
        const double r1 = rot1 - rng.normal(0.0, sd_rot1);
        const double t = trans - rng.normal(0.0, sd_trans);
        const double r2 = rot2 - rng.normal(0.0, sd_rot2);
        Pose2& q = particles[i];
        q = Pose2(q.x + t * std::cos(q.theta + r1), q.y + t * std::sin(q.theta + r1), q.theta + r1 + r2);
      }
    }, 2048);
    return;
  }
  // nav2's omnidirectional model.
  const double rot = angle_difference(b.theta, a.theta);
  const double sd_trans = std::sqrt(p.alpha3 * trans * trans + p.alpha1 * rot * rot);
  const double sd_rot = std::sqrt(p.alpha4 * rot * rot + p.alpha2 * trans * trans);
  const double sd_strafe = std::sqrt(p.alpha1 * rot * rot + p.alpha5 * trans * trans);
  const double bearing = trans < kTurnOnTheSpot ? 0.0 : angle_difference(std::atan2(dy, dx), a.theta);
  parallel_for(n, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      StreamRandom rng(seed, i);
      Pose2& q = particles[i];
      const double heading = q.theta + bearing;
      const double c = std::cos(heading), s = std::sin(heading);
      const double t = trans + rng.normal(0.0, sd_trans);
      const double r = rot + rng.normal(0.0, sd_rot);
      const double side = rng.normal(0.0, sd_strafe);
      q = Pose2(q.x + t * c - side * s, q.y + t * s + side * c, q.theta + r);
    }
  }, 2048);
}

}  // namespace kiseki
