// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The Monte Carlo engine: resampling, KLD, motion models, range casting, the beam and
// likelihood-field models against brute force, the engine on a small synthetic room, and the
// global correlative scan matcher against exhaustive search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <vector>

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

namespace {

// A 10 m x 6 m room (0.05 m cells) with walls, an L-shaped block and a pillar: no symmetry.
OccupancyGrid room() {
  OccupancyGrid g(200, 120, 0.05, Pose2(-1.0, -0.5, 0.0), kFree);
  for (int x = 0; x < 200; ++x) g.set(x, 0, kOccupied), g.set(x, 119, kOccupied);
  for (int y = 0; y < 120; ++y) g.set(0, y, kOccupied), g.set(199, y, kOccupied);
  for (int x = 40; x < 90; ++x) g.set(x, 40, kOccupied);
  for (int y = 40; y < 80; ++y) g.set(89, y, kOccupied);
  for (int x = 140; x < 150; ++x)
    for (int y = 70; y < 80; ++y) g.set(x, y, kOccupied);
  for (int x = 160; x < 199; ++x)
    for (int y = 0; y < 10; ++y) g.set(x, y, kUnknown);
  return g;
}

std::vector<double> scan_angles(int n) {
  std::vector<double> a(n);
  for (int i = 0; i < n; ++i) a[i] = -kPi / 2 + kPi * i / (n - 1);
  return a;
}

std::vector<float> cast(const OccupancyGrid& g, const Pose2& sensor, const std::vector<double>& angles, double max_range) {
  RayCastOptions o;
  o.max_range = max_range;
  std::vector<double> r(angles.size());
  cast_scan(g, sensor, angles.data(), angles.size(), o, r.data());
  return std::vector<float>(r.begin(), r.end());
}

}  // namespace

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

TEST(LikelihoodField, TableEqualsTheFormulaAtEveryBeamEnd) {
  OccupancyGrid g = room();
  g.set_origin(Pose2(-1.0, -0.5, 0.3));
  const cv::Mat dist = distance_field(g);
  const auto angles = scan_angles(37);
  std::vector<float> ranges(37);
  for (int i = 0; i < 37; ++i) ranges[i] = 0.5f + 0.1f * i;
  ranges[3] = NAN, ranges[4] = 30.0f, ranges[5] = -1.0f;  // skipped: invalid, no return, invalid
  for (auto comb : {BeamCombination::product, BeamCombination::nav2}) {
    LikelihoodFieldParams p;
    p.combination = comb;
    p.sensor = Pose2(0.2, -0.1, 0.05);
    LikelihoodFieldModel m(g, p);
    m.set_scan(angles.data(), ranges.data(), ranges.size(), 30.0);
    EXPECT_EQ(m.readings(), 34u);
    const std::vector<Pose2> poses = {Pose2(2, 2, 0.4), Pose2(7, 1, -2.0), Pose2(30, 30, 0)};
    std::vector<double> got(3);
    m.log_likelihoods(poses.data(), 3, got.data());
    for (int k = 0; k < 3; ++k) {
      const Pose2 s = poses[k].compose(p.sensor);
      double sum = 0;
      for (int i = 0; i < 37; ++i) {
        if (i >= 3 && i <= 5) continue;
        const double a = s.theta + angles[i];
        const CellIndex c = g.world_to_cell({s.x + ranges[i] * std::cos(a), s.y + ranges[i] * std::sin(a)});
        const double d = g.contains(c) ? std::min<double>(dist.at<float>(c.y, c.x), 2.0) : 2.0;
        const double gd = std::exp(-d * d / (2 * 0.2 * 0.2));
        if (comb == BeamCombination::product) {
          sum += std::log(0.95 * gd / (std::sqrt(2 * kPi) * 0.2) + 0.05 / 30.0);
        } else {
          sum += std::pow(0.95 * gd + 0.05 / 30.0, 3);
        }
      }
      const double want = comb == BeamCombination::product ? sum : std::log(1.0 + sum);
      EXPECT_NEAR(got[k], want, 1e-4 * std::max(1.0, std::abs(want)));
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
  BeamModelParams p;
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

namespace {

double error(const Pose2& a, const Pose2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

struct DriveLog {
  std::vector<Pose2> estimates;
  std::vector<std::size_t> counts;
  std::vector<double> reliability;
};

// Drives a robot around the room; the filter sees scans cast from the truth. If kidnap >= 0, the
// robot is carried to `kidnap_to` at that step without the odometry knowing.
DriveLog drive(MclParams params, std::uint64_t seed, bool global, int steps, int kidnap = -1,
          Pose2 kidnap_to = {}) {
  const OccupancyGrid g = room();
  const auto angles = scan_angles(61);
  const cv::Mat clearance = distance_field(g);
  LikelihoodFieldModel model(g, {});
  MonteCarloLocalization mcl(params, seed);
  mcl.set_free_space(g);
  Pose2 truth(1.0, 4.5, 0.0), odom = truth;
  if (global) mcl.initialize_uniform();
  else mcl.initialize_gaussian(truth, 0.1, 0.1, 0.05);
  DriveLog run;
  for (int k = 0; k < steps; ++k) {
    const Pose2 step(0.1, 0.0, k % 60 < 30 ? 0.05 : -0.05);
    const Pose2 next = truth.compose(step);
    const CellIndex c = g.world_to_cell({next.x, next.y});
    if (g.contains(c) && clearance.at<float>(c.y, c.x) > 0.4f) {  // a robot keeps 0.4 m from walls
      mcl.predict(odom, odom.compose(step));
      truth = next, odom = odom.compose(step);
    } else {
      const Pose2 turn(0.0, 0.0, 0.5);
      mcl.predict(odom, odom.compose(turn));
      truth = truth.compose(turn), odom = odom.compose(turn);
    }
    if (k == kidnap) truth = kidnap_to;
    const auto ranges = cast(g, truth, angles, 8.0);
    model.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
    const UpdateReport rep = mcl.update(model);
    run.estimates.push_back(mcl.estimate());
    run.counts.push_back(mcl.particles().size());
    run.reliability.push_back(mcl.reliability());
    if (k + 1 == steps) run.estimates.push_back(truth);  // the last entry: the final truth
  }
  return run;
}

}  // namespace

TEST(MonteCarloLocalization, TracksAndIsDeterministicForAnyThreadCount) {
  MclParams p;
  p.particles = 3000;
  p.threads = 1;
  const DriveLog one = drive(p, 9, false, 60);
  p.threads = 2;
  const DriveLog two = drive(p, 9, false, 60);
  ASSERT_EQ(one.estimates.size(), two.estimates.size());
  for (std::size_t i = 0; i < one.estimates.size(); ++i) {
    ASSERT_EQ(one.estimates[i].x, two.estimates[i].x);
    ASSERT_EQ(one.estimates[i].theta, two.estimates[i].theta);
  }
  EXPECT_LT(error(one.estimates[one.estimates.size() - 2], one.estimates.back()), 0.1);
  EXPECT_GT(one.reliability.back(), 0.9);
}

TEST(MonteCarloLocalization, GlobalLocalizationWithKldEndsWithFewParticles) {
  MclParams p;
  p.particles = 20000;
  p.kld = true;
  p.kld_params.min_particles = 300;
  p.resample_threshold = 1.0;
  p.likelihood_power = 0.1;  // a sparse uniform start: temper the 61 beams (as kiseki's global)
  const DriveLog run = drive(p, 3, true, 80);
  EXPECT_LT(error(run.estimates[run.estimates.size() - 2], run.estimates.back()), 0.2);
  EXPECT_LT(run.counts[run.counts.size() - 1], 2000u);  // converged: few bins
  EXPECT_GE(run.counts.back(), 300u);
  // A flat likelihood leaves the cloud spread over the room's ~8,600 bins: the bound asks for
  // more than the maximum.
  MonteCarloLocalization flat(p, 4);
  flat.set_free_space(room());
  flat.initialize_uniform();
  flat.update(std::vector<double>(20000, -1.0), 1, NAN);
  EXPECT_EQ(flat.particles().size(), 20000u);
}

TEST(MonteCarloLocalization, ResettingRecoversFromAKidnappingAndTheReliabilityFallsWithout) {
  MclParams p;
  p.particles = 2000;
  p.recovery = Recovery::none;
  const Pose2 elsewhere(7.5, 1.0, 2.0);
  const DriveLog lost = drive(p, 5, false, 100, 30, elsewhere);
  EXPECT_GT(error(lost.estimates[lost.estimates.size() - 2], lost.estimates.back()), 1.0);
  EXPECT_GT(lost.reliability[29], 0.9);
  EXPECT_LT(lost.reliability.back(), 0.2);  // lost, and it says so
  p.recovery = Recovery::resetting;
  const DriveLog found = drive(p, 5, false, 100, 30, elsewhere);
  EXPECT_LT(error(found.estimates[found.estimates.size() - 2], found.estimates.back()), 0.2);
  EXPECT_GT(found.reliability.back(), 0.8);
}

// A measurement seen only through its likelihood: log p = -|pose - target|^2 / (2 0.3^2) (position
// in m and heading in rad alike) plus `ripple` sin(3x) cos(2y), over 30 readings, with a fixed
// agreement with the map.
class TargetModel : public SensorModel {
 public:
  Pose2 target;
  double peak = 1.0;  ///< 0: a flat likelihood (the ripple only)
  double ripple = 0.0;
  double agree = 1.0;
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override {
    for (std::size_t i = 0; i < n; ++i) {
      const Pose2& q = poses[i];
      const double d2 = std::pow(q.x - target.x, 2) + std::pow(q.y - target.y, 2) +
                        std::pow(angle_difference(q.theta, target.theta), 2);
      out[i] = -0.5 * peak * d2 / 0.09 + ripple * std::sin(3 * q.x) * std::cos(2 * q.y);
    }
  }
  std::size_t readings() const override { return 30; }
  double agreement(const Pose2&) const override { return agree; }
};

TEST(MonteCarloLocalization, ALikelihoodDropResetsACloudCarriedToAPlaceThatLooksAlike) {
  // The scans go on agreeing with the map (agreement 1), but the robot is elsewhere: only the
  // likelihood has dropped against its long-term average.
  for (const double drop : {0.0, 0.5}) {
    MclParams p;
    p.particles = 1000;
    p.recovery = Recovery::resetting;
    p.reset_likelihood_drop = drop;
    MonteCarloLocalization mcl(p, 11);
    mcl.set_free_space(room());
    TargetModel model;
    model.target = Pose2(1.0, 4.5, 0.0);
    mcl.initialize_gaussian(model.target, 0.1, 0.1, 0.05);
    for (int k = 0; k < 20; ++k) mcl.update(model);
    model.target = Pose2(7.5, 1.0, 2.0);
    int sensor_resets = 0;
    for (int k = 0; k < 30; ++k) sensor_resets += mcl.update(model).reset == "sensor";
    if (drop == 0.0) {
      EXPECT_EQ(sensor_resets, 0);
      EXPECT_GT(error(mcl.estimate(), model.target), 3.0);  // agreement alone cannot see it
    } else {
      EXPECT_GE(sensor_resets, 1);
      EXPECT_LT(error(mcl.estimate(), model.target), 0.3);
    }
  }
}

TEST(MonteCarloLocalization, AResetNeedsEvidenceWhereTheLikelihoodIsFlat) {
  // Every scan disagrees with the map (agreement 0), but the likelihood is flat to within
  // 0.8 nats everywhere: the best of 20,000 uniform candidates beats the cloud's best by
  // chance. With the default margin (a Bayes factor of 10) no reset is kept and the cloud
  // stays; without one, the resets scatter it over the room.
  for (const double evidence : {0.0, MclParams{}.reset_evidence}) {
    MclParams p;
    p.particles = 1000;
    p.recovery = Recovery::resetting;
    p.reset_evidence = evidence;
    MonteCarloLocalization mcl(p, 12);
    mcl.set_free_space(room());
    TargetModel model;
    model.peak = 0.0;
    model.ripple = 0.4;
    model.agree = 0.0;
    const Pose2 start(1.0, 4.5, 0.0);
    mcl.initialize_gaussian(start, 0.1, 0.1, 0.05);
    int resets = 0;
    for (int k = 0; k < 30; ++k) resets += mcl.update(model).reset != "none";
    if (evidence > 0.0) {
      EXPECT_EQ(resets, 0);
      EXPECT_LT(error(mcl.estimate(), start), 0.5);  // the ripple alone moves it a little
    } else {
      EXPECT_GT(resets, 0);
      EXPECT_GT(error(mcl.estimate(), start), 1.0);
    }
  }
  MclParams bad;
  bad.reset_evidence = -1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = MclParams{};
  bad.reset_likelihood_drop = 1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(MonteCarloLocalization, WeightsCanBeSetAndBadInputIsRefused) {
  MclParams p;
  p.particles = 4;
  MonteCarloLocalization mcl(p, 1);
  EXPECT_THROW(mcl.estimate(), std::logic_error);
  mcl.set_particles({Pose2(0, 0, 0), Pose2(1, 0, 0), Pose2(2, 0, 0), Pose2(3, 0, 0)}, {1, 1, 2, 0});
  EXPECT_NEAR(mcl.weights()[2], 0.5, 1e-12);
  EXPECT_NEAR(mcl.estimate().x, (0 + 1 + 4) / 4.0, 1e-12);
  EXPECT_THROW(mcl.set_weights({1, 1}), std::invalid_argument);
  EXPECT_THROW(mcl.set_weights({0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(mcl.set_particles({Pose2(NAN, 0, 0)}), std::invalid_argument);
  EXPECT_THROW(mcl.predict(Pose2(0, 0, 0), Pose2(100, 0, 0)), std::invalid_argument);
  EXPECT_THROW(mcl.update({0.0, NAN, 0.0, 0.0}, 1, NAN), std::invalid_argument);
  EXPECT_THROW(mcl.initialize_uniform(), std::logic_error);  // no free space set
  OccupancyGrid walls(3, 3, 0.1, Pose2(), kOccupied);
  EXPECT_THROW(mcl.set_free_space(walls), std::invalid_argument);
  MclParams bad;
  bad.particles = 0;
  EXPECT_THROW(MonteCarloLocalization(bad, 1), std::invalid_argument);
}

TEST(MonteCarloLocalization, AnOdometryJumpOverTheLimitIsRefusedAndOneJustUnderIsAMotion) {
  MclParams p;
  p.particles = 10;
  MonteCarloLocalization mcl(p, 1);
  mcl.initialize_gaussian(Pose2(0, 0, 0), 0.0, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(kMaxOdometryJump, 10.0);
  const double under = kMaxOdometryJump - 0.01, over = kMaxOdometryJump + 0.01;
  EXPECT_NO_THROW(mcl.predict(Pose2(0, 0, 0), Pose2(0.6 * under, 0.8 * under, 0)));
  try {
    mcl.predict(Pose2(0, 0, 0), Pose2(0.6 * over, 0.8 * over, 0));
    FAIL() << "a jump of " << over << " m was taken as a motion";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "MCL: odometry jumps 10.01 m between two updates: more than kiseki's limit of 10 m");
  }
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

namespace {

struct Scored {
  double score;
  long long index;
  int x, y, k;
  Pose2 pose;
};

// Every lattice pose scored by the likelihood field itself (with a disc, only the poses on its
// side), then the greedy selection: the best, then the best not within both min_distance and
// min_angle of one taken.
std::vector<Scored> exhaustive(const OccupancyGrid& map, const CorrelativeScanMatcher& m, const std::vector<double>& angles,
                               const std::vector<float>& ranges, const SearchDisc* disc = nullptr) {
  const auto& p = m.params();
  LikelihoodFieldModel field(map, p.likelihood);
  field.set_scan(angles.data(), ranges.data(), angles.size(), m.max_range());
  const int headings = m.headings(angles.data(), ranges.data(), angles.size());
  std::vector<Scored> all;
  std::vector<Pose2> poses;
  for (int k = 0; k < headings; ++k)
    for (int y = 0; y < map.height(); ++y)
      for (int x = 0; x < map.width(); ++x) {
        if (p.free_only && !(map.value(x, y) >= 0 && map.value(x, y) < 20)) continue;  // known free only
        const Pose2 pose = m.lattice_pose(x, y, k, headings);
        if (disc && (std::hypot(pose.x - disc->x, pose.y - disc->y) <= disc->radius) != disc->inside) continue;
        poses.push_back(pose);
        all.push_back({0.0, (static_cast<long long>(k) * map.height() + y) * map.width() + x, x, y, k, poses.back()});
      }
  std::vector<double> ll(poses.size());
  field.log_likelihoods(poses.data(), poses.size(), ll.data());
  for (std::size_t i = 0; i < all.size(); ++i) all[i].score = ll[i];
  std::sort(all.begin(), all.end(), [](const Scored& a, const Scored& b) {
    return a.score > b.score || (a.score == b.score && a.index < b.index);
  });
  std::vector<Scored> taken;
  for (const auto& s : all) {
    if (taken.size() == static_cast<std::size_t>(p.hypotheses)) break;
    bool near = false;
    for (const auto& t : taken) {
      near = near || (std::hypot(s.pose.x - t.pose.x, s.pose.y - t.pose.y) < p.min_distance &&
                      std::abs(normalize_angle(s.pose.theta - t.pose.theta)) < p.min_angle);
    }
    if (!near) taken.push_back(s);
  }
  return taken;
}

}  // namespace

TEST(CorrelativeScanMatcher, EqualsExhaustiveSearchOnRandomSmallMaps) {
  int disc_searches_with_a_result = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    Random rng(seed);
    const int w = 17 + static_cast<int>(rng.below(12)), h = 13 + static_cast<int>(rng.below(12));
    OccupancyGrid map(w, h, 0.1, Pose2(rng.uniform(-2, 2), rng.uniform(-2, 2), seed % 2 ? 0.0 : rng.uniform(-3, 3)), kFree);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double u = rng.uniform();
        if (u < 0.12) map.set(x, y, kOccupied);
        else if (u < 0.17) map.set(x, y, kUnknown);
      }
    std::vector<double> angles(20 + rng.below(20));
    std::vector<float> ranges(angles.size());
    for (std::size_t i = 0; i < angles.size(); ++i) {
      angles[i] = rng.uniform(-kPi, kPi);
      ranges[i] = rng.uniform() < 0.1 ? std::numeric_limits<float>::infinity() : static_cast<float>(rng.uniform(0.1, 2.4));
    }
    CorrelativeMatcherParams p;
    p.depth = static_cast<int>(seed % 4);  // 0 (no branching) .. 3 (8 x 8 cells per coarse node)
    p.hypotheses = 1 + static_cast<int>(seed % 4);
    p.min_distance = rng.uniform(0.0, 0.6);
    p.min_angle = rng.uniform(0.1, 1.5);
    p.angular_step = seed % 3 == 0 ? 0.0 : rng.uniform(0.05, 0.3);
    p.likelihood.max_beams = seed % 2 ? 0 : 12;
    p.likelihood.sigma_hit = rng.uniform(0.05, 0.3);
    if (seed == 4) p.likelihood.sensor = Pose2(0.15, -0.05, 0.3);
    p.free_only = seed % 3 != 1;
    p.threads = 1;
    const CorrelativeScanMatcher one(map, 2.5, p);
    const auto got = one.match(angles.data(), ranges.data(), angles.size());
    const auto want = exhaustive(map, one, angles, ranges);
    ASSERT_EQ(got.size(), want.size()) << "seed " << seed;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].cell_x, want[i].x) << "seed " << seed << " hypothesis " << i;
      EXPECT_EQ(got[i].cell_y, want[i].y) << "seed " << seed << " hypothesis " << i;
      EXPECT_EQ(got[i].heading, want[i].k) << "seed " << seed << " hypothesis " << i;
      EXPECT_NEAR(got[i].score, want[i].score, 1e-9) << "seed " << seed << " hypothesis " << i;
    }
    // Restricted to one side of a disc (alternately inside and beyond it), still exact.
    const Eigen::Vector2d centre = map.origin().transform_point({rng.uniform(0.0, 0.1 * w), rng.uniform(0.0, 0.1 * h)});
    const SearchDisc disc{centre.x(), centre.y(), rng.uniform(0.3, 1.0), seed % 2 == 0};
    const auto got_disc = one.match(angles.data(), ranges.data(), angles.size(), &disc);
    const auto want_disc = exhaustive(map, one, angles, ranges, &disc);
    ASSERT_EQ(got_disc.size(), want_disc.size()) << "seed " << seed << " with a disc";
    disc_searches_with_a_result += !got_disc.empty();
    for (std::size_t i = 0; i < got_disc.size(); ++i) {
      EXPECT_EQ(got_disc[i].cell_x, want_disc[i].x) << "seed " << seed << " disc hypothesis " << i;
      EXPECT_EQ(got_disc[i].cell_y, want_disc[i].y) << "seed " << seed << " disc hypothesis " << i;
      EXPECT_EQ(got_disc[i].heading, want_disc[i].k) << "seed " << seed << " disc hypothesis " << i;
      EXPECT_NEAR(got_disc[i].score, want_disc[i].score, 1e-9) << "seed " << seed << " disc hypothesis " << i;
    }
    p.threads = 2;
    const auto two = CorrelativeScanMatcher(map, 2.5, p).match(angles.data(), ranges.data(), angles.size());
    ASSERT_EQ(two.size(), got.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(two[i].score, got[i].score);
      EXPECT_EQ(two[i].pose.x, got[i].pose.x);
      EXPECT_EQ(two[i].pose.y, got[i].pose.y);
      EXPECT_EQ(two[i].pose.theta, got[i].pose.theta);
    }
  }
  EXPECT_EQ(disc_searches_with_a_result, 6);  // no disc left its side empty
}

TEST(CorrelativeScanMatcher, RecoversAScanSimulatedAtALatticePoseOfAStructuredMap) {
  const OccupancyGrid map = room();
  const auto angles = scan_angles(361);
  CorrelativeMatcherParams p;
  p.likelihood.max_beams = 60;
  p.angular_step = 2.0 * kPi / 360;
  p.hypotheses = 3;
  const CorrelativeScanMatcher m(map, 8.0, p);
  Random rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    // a lattice pose on a free cell of the room, away from the walls
    int x, y;
    do {
      x = 10 + static_cast<int>(rng.below(180)), y = 10 + static_cast<int>(rng.below(100));
    } while (map.value(x, y) != kFree || map.value(x + 2, y) != kFree || map.value(x, y + 2) != kFree);
    const int k = static_cast<int>(rng.below(360));
    const Pose2 truth = m.lattice_pose(x, y, k, 360);
    const auto ranges = cast(map, truth, angles, 8.0);
    const auto got = m.match(angles.data(), ranges.data(), angles.size());
    ASSERT_FALSE(got.empty());
    EXPECT_LE(std::hypot(got[0].pose.x - truth.x, got[0].pose.y - truth.y), map.resolution() + 1e-9) << "trial " << trial;
    EXPECT_LE(std::abs(normalize_angle(got[0].pose.theta - truth.theta)), p.angular_step + 1e-9) << "trial " << trial;
    for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LE(got[i].score, got[i - 1].score);
  }
}

TEST(CorrelativeScanMatcher, BadInputIsRefused) {
  const OccupancyGrid map = room();
  CorrelativeMatcherParams p;
  p.hypotheses = 0;
  EXPECT_THROW(CorrelativeScanMatcher(map, 8.0, p), std::invalid_argument);
  p = {};
  p.depth = 17;
  EXPECT_THROW(CorrelativeScanMatcher(map, 8.0, p), std::invalid_argument);
  p = {};
  p.angular_step = -0.1;
  EXPECT_THROW(CorrelativeScanMatcher(map, 8.0, p), std::invalid_argument);
  EXPECT_THROW(CorrelativeScanMatcher(map, 0.0, {}), std::invalid_argument);
  EXPECT_THROW(CorrelativeScanMatcher(OccupancyGrid(5, 5, 0.1, Pose2(), kOccupied), 8.0, {}), std::invalid_argument);
  const CorrelativeScanMatcher m(map, 8.0, {});
  const std::vector<double> a = {0.0};
  const std::vector<float> none = {std::numeric_limits<float>::infinity()};
  EXPECT_TRUE(m.match(a.data(), none.data(), 1).empty());
}
