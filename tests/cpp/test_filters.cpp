// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The Monte Carlo engine: resampling, KLD, motion models, range casting, the beam model against
// brute force, and the travel-distance filter (the likelihood field: test_likelihood_field.cpp;
// the engine on a room: test_monte_carlo_localization.cpp; the correlative scan matcher:
// test_relocalization.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <vector>

#include "filter_scenes.hpp"
#include "kiseki/core/angle.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/filters/correlative_scan_matcher.hpp"
#include "kiseki/filters/kld_sampling.hpp"
#include "kiseki/filters/monte_carlo_localization.hpp"
#include "kiseki/filters/motion_model.hpp"
#include "kiseki/filters/resampling.hpp"
#include "kiseki/filters/travel_distance_filter.hpp"
#include "kiseki/grid/distance_field.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "kiseki/models/beam_model.hpp"
#include "kiseki/models/likelihood_field.hpp"

using namespace kiseki;
using namespace kiseki::test;

TEST(Resampling, EveryMethodCopiesParticlesInProportionToTheirWeights) {
  const std::vector<double> w = {0.1, 0.4, 0.05, 0.25, 0.2};
  for (auto method : {ResamplingMethod::multinomial, ResamplingMethod::systematic,
                      ResamplingMethod::stratified, ResamplingMethod::residual}) {
    Random rng(7);
    std::vector<double> counts(w.size(), 0.0);
    const int reps = 2000, n = 100;
    for (int r = 0; r < reps; ++r) {
      const auto idx = resample_indices(w, n, method, rng);
      ASSERT_EQ(idx.size(), static_cast<std::size_t>(n));
      std::vector<int> c(w.size(), 0);
      for (auto i : idx) ++c[i];
      for (std::size_t i = 0; i < w.size(); ++i) {
        counts[i] += c[i];
        if (method == ResamplingMethod::systematic || method == ResamplingMethod::residual) {
          // Low-variance schemes: never fewer than floor(n w) - 1 (systematic) / floor(n w) copies.
          EXPECT_GE(c[i], static_cast<int>(std::floor(n * w[i])) - (method == ResamplingMethod::systematic ? 1 : 0));
        }
      }
    }
    for (std::size_t i = 0; i < w.size(); ++i) {
      EXPECT_NEAR(counts[i] / (reps * n), w[i], 0.005) << resampling_method_name(method) << " particle " << i;
    }
  }
}

TEST(Resampling, NamesRoundTripAndBadInputIsRefused) {
  for (const char* name : {"multinomial", "systematic", "stratified", "residual"}) {
    EXPECT_STREQ(resampling_method_name(resampling_method_from_name(name)), name);
  }
  EXPECT_THROW(resampling_method_from_name("best"), std::invalid_argument);
  Random rng(1);
  EXPECT_THROW(resample_indices({0.0, 0.0}, 3, ResamplingMethod::systematic, rng), std::invalid_argument);
  EXPECT_THROW(resample_indices({1.0, NAN}, 3, ResamplingMethod::systematic, rng), std::invalid_argument);
  EXPECT_THROW(resample_indices({}, 3, ResamplingMethod::systematic, rng), std::invalid_argument);
}

TEST(Weights, LogLikelihoodsAreAppliedWithoutUnderflow) {
  std::vector<double> w = {0.25, 0.25, 0.25, 0.25};
  // Log-likelihoods of -1000: exp underflows, their ratios do not.
  ASSERT_TRUE(apply_log_likelihoods(w, {-1000.0, -1001.0, -1002.0, -INFINITY}, 1.0));
  const double z = 1 + std::exp(-1.0) + std::exp(-2.0);
  EXPECT_NEAR(w[0], 1 / z, 1e-12);
  EXPECT_NEAR(w[1], std::exp(-1.0) / z, 1e-12);
  EXPECT_EQ(w[3], 0.0);
  EXPECT_NEAR(effective_sample_size(w), 1.0 / (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), 1e-12);
  std::vector<double> u = {0.5, 0.5};
  EXPECT_FALSE(apply_log_likelihoods(u, {-INFINITY, -INFINITY}, 1.0));
  EXPECT_EQ(u[0], 0.5);
  EXPECT_THROW(apply_log_likelihoods(u, {NAN, 0.0}, 1.0), std::invalid_argument);
  EXPECT_THROW(apply_log_likelihoods(u, {0.0}, 1.0), std::invalid_argument);
}

TEST(Weights, EqualWeightsShareOneLogWithTheBitsOfALogEach) {
  // The reference: w_i <- w_i l_i^power / sum, with log w_i taken for every particle.
  const auto reference = [](std::vector<double> w, const std::vector<double>& log_l, double power) {
    double top = -INFINITY, total = 0.0;
    for (std::size_t i = 0; i < w.size(); ++i) {
      if (w[i] > 0.0) top = std::max(top, power * log_l[i] + std::log(w[i]));
    }
    std::vector<double> e(w.size());
    for (std::size_t i = 0; i < w.size(); ++i) {
      e[i] = w[i] > 0.0 ? std::exp(power * log_l[i] + std::log(w[i]) - top) : 0.0;
      total += e[i];
    }
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = e[i] / total;
    return w;
  };
  Random rng(3);
  std::vector<double> log_l(500), runs(500);
  for (std::size_t i = 0; i < 500; ++i) {
    log_l[i] = rng.uniform(-900.0, -300.0);
    runs[i] = i % 7 == 3 ? 0.0 : (i < 200 ? 0.002 : rng.uniform());  // equal, zero and distinct
  }
  log_l[42] = -INFINITY;
  for (const std::vector<double>& w0 : {std::vector<double>(500, 1.0 / 500.0), runs}) {
    for (double power : {1.0, 0.3}) {
      std::vector<double> w = w0;
      ASSERT_TRUE(apply_log_likelihoods(w, log_l, power));
      const std::vector<double> want = reference(w0, log_l, power);
      for (std::size_t i = 0; i < w.size(); ++i) ASSERT_EQ(w[i], want[i]) << i;
    }
  }
}

TEST(Kld, BoundMatchesFoxsFormulaAndGrowsWithTheBins) {
  // k = 10, err = 0.05, z = 0.99 computed by hand from eq. 14.
  const double a = 2.0 / 81.0, b = 1.0 - a + std::sqrt(a) * 0.99;
  EXPECT_EQ(kld_sample_bound(10, 0.05, 0.99), static_cast<std::size_t>(std::ceil(9.0 / 0.1 * b * b * b)));
  EXPECT_EQ(kld_sample_bound(1, 0.05, 0.99), 0u);
  std::size_t prev = 0;
  for (std::size_t k : {2, 5, 50, 500, 5000}) {
    const std::size_t n = kld_sample_bound(k, 0.05, 0.99);
    EXPECT_GT(n, prev);
    prev = n;
  }
  EXPECT_THROW(kld_sample_bound(10, 0.0, 0.99), std::invalid_argument);
}

TEST(MotionModel, SameSeedSameParticlesForAnyThreadCount) {
  MotionParams p;
  for (auto type : {MotionModelType::differential, MotionModelType::omnidirectional}) {
    p.type = type;
    std::vector<Pose2> a(20000, Pose2(1, 2, 0.3)), b = a;
    sample_motion(p, Pose2(0, 0, 0), Pose2(0.5, 0.1, 0.2), a.data(), a.size(), 42, 1);
    sample_motion(p, Pose2(0, 0, 0), Pose2(0.5, 0.1, 0.2), b.data(), b.size(), 42, 2);
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].x, b[i].x);
      ASSERT_EQ(a[i].theta, b[i].theta);
    }
  }
}

TEST(MotionModel, WithoutNoiseParticlesMoveByTheIncrementInTheirOwnFrame) {
  MotionParams p;
  p.alpha1 = p.alpha2 = p.alpha3 = p.alpha4 = p.alpha5 = 0.0;
  const Pose2 before(1, 1, 0.5), after(1.4, 1.3, 0.9), start(-2, 3, -1.0);
  const Pose2 want = start.compose(before.between(after));
  for (auto type : {MotionModelType::differential, MotionModelType::omnidirectional}) {
    p.type = type;
    std::vector<Pose2> q = {start};
    sample_motion(p, before, after, q.data(), 1, 3, 1);
    EXPECT_NEAR(q[0].x, want.x, 1e-12);
    EXPECT_NEAR(q[0].y, want.y, 1e-12);
    EXPECT_NEAR(angle_difference(q[0].theta, want.theta), 0.0, 1e-12);
  }
}

TEST(MotionModel, DifferentialNoiseHasTheModelsSpread) {
  MotionParams p;  // alpha3 = 0.05: SD of the translation sqrt(0.05) * 1 m for a straight 1 m move
  std::vector<Pose2> q(100000, Pose2());
  sample_motion(p, Pose2(), Pose2(1, 0, 0), q.data(), q.size(), 5, 0);
  double m = 0, v = 0;
  for (const auto& x : q) m += x.x;
  m /= q.size();
  for (const auto& x : q) v += (x.x - m) * (x.x - m);
  v /= q.size();
  EXPECT_NEAR(m, 1.0, 0.01);
  // x = t cos(r1): var(t) = 0.05 plus a little from the heading noise (alpha2 = 0.01).
  EXPECT_NEAR(v, 0.05, 0.004);
}

TEST(RangeCaster, EqualsTheCellWalkOfCastRay) {
  const OccupancyGrid g = room();
  for (bool unknown : {false, true}) {
    RangeCaster caster(g, unknown);
    RayCastOptions o;
    o.unknown_is_obstacle = unknown;
    o.max_range = 12.0;
    Random rng(11);
    for (int k = 0; k < 3000; ++k) {
      const double x = rng.uniform(-1.5, 9.5), y = rng.uniform(-1.0, 6.0), h = rng.uniform(-kPi, kPi);
      const double want = cast_ray(g, {x, y}, h, o).range;
      ASSERT_NEAR(caster.range(x, y, h, o.max_range), want, 1e-9) << x << " " << y << " " << h;
    }
  }
}

TEST(BeamModel, EqualsTheMixtureWithRaysCastCellByCell) {
  const OccupancyGrid g = room();
  const auto angles = scan_angles(21);
  const Pose2 truth(3.0, 2.5, 0.7);
  auto ranges = cast(g, truth, angles, 8.0);
  ranges[2] = INFINITY;  // no return
  ranges[3] = NAN;       // invalid
  for (RayCasterKind caster : {RayCasterKind::distance_field, RayCasterKind::swept_sector}) {
    BeamModelParams p;
    p.caster = caster;
    BeamModel m(g, p);
    m.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
    EXPECT_EQ(m.readings(), 20u);
    RayCastOptions o;
    o.max_range = 8.0;
    o.unknown_is_obstacle = true;
    const std::vector<Pose2> poses = {truth, Pose2(3.3, 2.4, 0.6), Pose2(6, 4, -1)};
    std::vector<double> got(3);
    m.log_likelihoods(poses.data(), 3, got.data());
    for (int k = 0; k < 3; ++k) {
      double sum = 0;
      for (int i = 0; i < 21; ++i) {
        if (i == 3) continue;
        const double zs = cast_ray(g, {poses[k].x, poses[k].y}, poses[k].theta + angles[i], o).range;
        const bool none = i == 2;
        const double z = none ? 8.0 : ranges[i];
        double pz = 0.5 * std::exp(-(z - zs) * (z - zs) / 0.08) / (std::sqrt(2 * kPi) * 0.2);
        if (z < zs) pz += 0.05 * 0.1 * std::exp(-0.1 * z);
        pz += none ? 0.05 : 0.5 / 8.0;
        sum += std::log(pz);
      }
      EXPECT_NEAR(got[k], sum, 1e-6);
    }
    EXPECT_GT(got[0], got[1]);
    EXPECT_GT(got[0], got[2]);
    EXPECT_NEAR(m.agreement(truth), 1.0, 1e-12);
    // 1 m further along the heading, the beams ahead pass through the walls they end at.
    EXPECT_LT(m.agreement(truth.compose(Pose2(1.0, 0.0, 0.0))), 0.8);
    EXPECT_EQ(m.agreement(Pose2(30, 30, 0)), 0.0);  // outside the map
  }
}

TEST(BeamModel, BothCastersGiveTheSameWeights) {
  // The swept-sector caster is exact: the weights equal the distance-field caster's to rounding
  // at poses anywhere in and around the room, for both combinations.
  const OccupancyGrid g = room();
  const auto angles = scan_angles(181);
  const auto ranges = cast(g, Pose2(3.0, 2.5, 0.7), angles, 8.0);
  std::vector<Pose2> poses;
  Random rng(4);
  for (int k = 0; k < 2000; ++k) poses.emplace_back(rng.uniform(-2, 10), rng.uniform(-1, 6.5), rng.uniform(-kPi, kPi));
  for (auto comb : {BeamCombination::product, BeamCombination::nav2}) {
    BeamModelParams p;
    p.combination = comb;
    p.caster = RayCasterKind::distance_field;
    BeamModel field(g, p);
    p.caster = RayCasterKind::swept_sector;
    BeamModel sector(g, p);
    std::vector<double> a(poses.size()), b(poses.size());
    field.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
    sector.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
    field.log_likelihoods(poses.data(), poses.size(), a.data());
    sector.log_likelihoods(poses.data(), poses.size(), b.data());
    for (std::size_t k = 0; k < poses.size(); ++k) ASSERT_NEAR(a[k], b[k], 1e-9 * std::max(1.0, std::abs(a[k]))) << k;
  }
}

TEST(BeamModel, AMapTooLargeForTheSectorTableCastsWithTheDistanceField) {
  // 8.4 million cells at 64 bytes are the 512 MB limit: one more row and the model falls back
  // to the distance field (the same z*), without building the table.
  const int width = 4096, rows = static_cast<int>(kMaxSectorTableBytes / 64 / width);
  EXPECT_EQ(BeamModel(room()).caster(), RayCasterKind::swept_sector);
  EXPECT_EQ(BeamModel(OccupancyGrid(width, rows + 1, 0.05)).caster(), RayCasterKind::distance_field);
  BeamModelParams p;
  p.caster = RayCasterKind::distance_field;
  EXPECT_EQ(BeamModel(room(), p).caster(), RayCasterKind::distance_field);
}

TEST(TravelDistanceFilter, ConvergesOnTheDistanceAGaussianLikelihoodPoints) {
  TravelDistanceParams p;
  p.particles = 2000;
  p.kld = true;
  p.kld_params.min_particles = 100;
  TravelDistanceFilter f(p, 4);
  f.initialize(0.0, 5.0);
  double truth = 0.0;
  for (int k = 0; k < 30; ++k) {
    f.predict(0.5, 0.05);
    truth += 0.5;
    std::vector<double> log_l(f.particles().size());
    for (std::size_t i = 0; i < log_l.size(); ++i) log_l[i] = -0.5 * std::pow((f.particles()[i] - truth) / 0.3, 2);
    f.update(log_l);
  }
  EXPECT_NEAR(f.estimate(), truth, 0.1);
  EXPECT_LT(f.particles().size(), 2000u);
  EXPECT_GE(f.particles().size(), 100u);
  p.threads = 1;
  TravelDistanceFilter a(p, 8), b(p, 8);
  p.threads = 2;
  TravelDistanceFilter c(p, 8);
  a.initialize(1, 1), c.initialize(1, 1);
  a.predict(1, 0.1), c.predict(1, 0.1);
  EXPECT_EQ(a.particles(), c.particles());
  EXPECT_THROW(b.predict(1, 0.1), std::logic_error);
}

TEST(TravelDistanceFilter, LikelihoodPowerLiesInTheMclsBound) {
  // the SE(2) engine's (0, 1000]: a power of 1e300 overflowed the log-likelihoods to NaN weights
  TravelDistanceParams p;
  for (double power : {1e-9, 0.1, 1.0, 1000.0}) {
    p.likelihood_power = power;
    EXPECT_NO_THROW(TravelDistanceFilter(p, 1)) << power;
  }
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (double power : {0.0, -1.0, 1000.0001, 1e300, inf, nan}) {
    p.likelihood_power = power;
    try {
      TravelDistanceFilter f(p, 1);
      ADD_FAILURE() << power << " was taken";
    } catch (const std::invalid_argument& e) {
      EXPECT_STREQ(e.what(), "travel distance filter: likelihood_power must lie in (0, 1000]") << power;
    }
  }
}

TEST(TravelDistanceFilter, EachScaleStaysWithItsDistanceThroughKldResampling) {
  TravelDistanceParams p;
  p.particles = 3000;
  p.kld = true;
  p.kld_params.min_particles = 100;
  TravelDistanceFilter f(p, 5);
  std::vector<double> d(3000), k(3000);
  for (std::size_t i = 0; i < d.size(); ++i) {
    d[i] = 0.0;
    k[i] = 0.5 + static_cast<double>(i) / 2000.0;  // 0.5 .. 2.0, one per particle
  }
  f.set_particles(d);
  f.set_scales(k);
  f.predict_scaled(4.0, 0.0, 0.0);  // d_i = 4 k_i exactly
  std::vector<double> log_l(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) log_l[i] = -0.5 * std::pow((f.particles()[i] - 4.4) / 0.2, 2);
  f.update(log_l);  // resampled (ESS far below n/2), KLD shrinks the count
  ASSERT_LT(f.particles().size(), 3000u);
  for (std::size_t j = 0; j < f.particles().size(); ++j) {
    EXPECT_DOUBLE_EQ(f.particles()[j], 4.0 * f.scales()[j]) << j;
    EXPECT_NEAR(f.scales()[j], 1.1, 0.2) << j;
  }
  // the scaled motion draws from per-particle streams: one result for any thread count
  p.kld = false;
  p.threads = 1;
  TravelDistanceFilter a(p, 9);
  p.threads = 2;
  TravelDistanceFilter b(p, 9);
  for (TravelDistanceFilter* g : {&a, &b}) {
    g->set_particles(d);
    g->set_scales(k);
    g->predict_scaled(1.0, 0.1, 0.01);
  }
  EXPECT_EQ(a.particles(), b.particles());
  EXPECT_EQ(a.scales(), b.scales());
  EXPECT_THROW(a.set_scales({1.0}), std::invalid_argument);
  EXPECT_THROW(a.predict_scaled(1.0, 0.1, -1.0), std::invalid_argument);
}
