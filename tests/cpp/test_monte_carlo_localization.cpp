// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The Monte Carlo localization engine on a small synthetic room: tracking for any thread count,
// global localization with KLD, resetting and the reliability, weights and bad input (resetting
// on a likelihood seen alone: test_resetting.cpp).
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

namespace {

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
  // 2 threads, and 0: chosen step by step between one thread and every core (ThreadChooser;
  // its first steps take each in turn, so a run mixes them)
  for (int threads : {2, 0}) {
    p.threads = threads;
    const DriveLog two = drive(p, 9, false, 60);
    ASSERT_EQ(one.estimates.size(), two.estimates.size());
    for (std::size_t i = 0; i < one.estimates.size(); ++i) {
      ASSERT_EQ(one.estimates[i].x, two.estimates[i].x) << threads;
      ASSERT_EQ(one.estimates[i].theta, two.estimates[i].theta) << threads;
    }
  }
  EXPECT_LT(position_error(one.estimates[one.estimates.size() - 2], one.estimates.back()), 0.1);
  EXPECT_GT(one.reliability.back(), 0.9);
}

TEST(MonteCarloLocalization, ManyParticlesSplitTheirExponentialsAndSinesAmongThreadsWithTheSameResult) {
  // 20,000 particles: the weights' and the average likelihood's exponentials, the mean's
  // cosines and sines and multinomial resampling's logarithms are split among the threads
  // (2 x kParallelExps and more), their sums taken in particle order.
  ASSERT_GT(20000u, 2 * kParallelExps);
  MclParams p;
  p.particles = 20000;
  p.resampling = ResamplingMethod::multinomial;
  p.resample_threshold = 1.0;
  p.recovery = Recovery::augmented;
  p.threads = 1;
  const DriveLog one = drive(p, 4, false, 6);
  for (int threads : {2, 3, 0}) {
    p.threads = threads;
    const DriveLog more = drive(p, 4, false, 6);
    for (std::size_t i = 0; i < one.estimates.size(); ++i) {
      ASSERT_EQ(one.estimates[i].x, more.estimates[i].x) << threads;
      ASSERT_EQ(one.estimates[i].y, more.estimates[i].y) << threads;
      ASSERT_EQ(one.estimates[i].theta, more.estimates[i].theta) << threads;
    }
    ASSERT_EQ(one.reliability, more.reliability) << threads;
  }
  // Without resampling the weights stay unequal: the posterior is the weighted mean summed in
  // particle order, as one thread sums it.
  const OccupancyGrid g = room();
  const auto angles = scan_angles(61);
  LikelihoodFieldModel model(g, {});
  p.resample_threshold = 0.0;
  p.recovery = Recovery::none;
  p.threads = 2;
  MonteCarloLocalization mcl(p, 8);
  const Pose2 truth(1.0, 4.5, 0.3);
  mcl.initialize_gaussian(truth, 0.3, 0.3, 0.2);
  const auto ranges = cast(g, truth, angles, 8.0);
  model.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
  mcl.update(model);
  double x = 0, y = 0, c = 0, s = 0;
  for (std::size_t i = 0; i < mcl.particles().size(); ++i) {
    const double w = mcl.weights()[i];
    x += w * mcl.particles()[i].x, y += w * mcl.particles()[i].y;
    c += w * std::cos(mcl.particles()[i].theta), s += w * std::sin(mcl.particles()[i].theta);
  }
  EXPECT_GT(mcl.weights()[0] / mcl.weights()[1] + mcl.weights()[1] / mcl.weights()[0], 2.0 + 1e-9);
  EXPECT_EQ(mcl.posterior().x, x);
  EXPECT_EQ(mcl.posterior().y, y);
  EXPECT_EQ(mcl.posterior().theta, Pose2(0.0, 0.0, std::atan2(s, c)).theta);  // wrapped as a Pose2 is
  EXPECT_EQ(mcl.estimate().x, x);
}

TEST(MonteCarloLocalization, GlobalLocalizationWithKldEndsWithFewParticles) {
  MclParams p;
  p.particles = 20000;
  p.kld = true;
  p.kld_params.min_particles = 300;
  p.resample_threshold = 1.0;
  p.likelihood_power = 0.1;  // a sparse uniform start: temper the 61 beams (as kiseki's global)
  const DriveLog run = drive(p, 3, true, 80);
  EXPECT_LT(position_error(run.estimates[run.estimates.size() - 2], run.estimates.back()), 0.2);
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
  EXPECT_GT(position_error(lost.estimates[lost.estimates.size() - 2], lost.estimates.back()), 1.0);
  EXPECT_GT(lost.reliability[29], 0.9);
  EXPECT_LT(lost.reliability.back(), 0.2);  // lost, and it says so
  p.recovery = Recovery::resetting;
  const DriveLog found = drive(p, 5, false, 100, 30, elsewhere);
  EXPECT_LT(position_error(found.estimates[found.estimates.size() - 2], found.estimates.back()), 0.2);
  EXPECT_GT(found.reliability.back(), 0.8);
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
  // KLD's err, z and bins are checked without kld too: parameters that hold a NaN are refused
  MclParams unused_kld;
  unused_kld.kld_params.err = NAN;
  EXPECT_THROW(unused_kld.validate(), std::invalid_argument);
  unused_kld.kld_params.err = 0.05;
  unused_kld.kld_params.z = 10.5;
  EXPECT_THROW(unused_kld.validate(), std::invalid_argument);
  unused_kld.kld_params.z = 10.0;
  unused_kld.kld_params.bin_xy = NAN;
  EXPECT_THROW(unused_kld.validate(), std::invalid_argument);
  unused_kld.kld_params.bin_xy = 0.5;
  unused_kld.kld_params.min_particles = 5000;  // above particles: used only with kld
  EXPECT_NO_THROW(unused_kld.validate());
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

// Beam skipping (the likelihood field's, nav2's idea): the engine has the model choose its beams
// from the cloud before weighing; beams ending in free space (a person the map does not hold)
// are skipped, and the choice and the weights are the same on one thread and on two.
TEST(BeamSkipping, TheEngineSkipsBeamsEndingInFreeSpaceTheSameForAnyThreadCount) {
  const OccupancyGrid g = room();
  const auto angles = scan_angles(61);
  const Pose2 truth(5.0, 0.8, kPi);  // facing the L-shaped block, the unknown corner behind
  auto ranges = cast(g, truth, angles, 8.0);
  for (int i = 25; i < 35; ++i) ranges[i] = 0.3f;  // 1 m or more from any wall
  LikelihoodFieldParams lp;
  lp.beam_skip = true;
  std::vector<std::vector<double>> weights;
  std::vector<std::vector<std::size_t>> used;
  for (int threads : {1, 2}) {
    LikelihoodFieldModel model(g, lp);
    model.set_scan(angles.data(), ranges.data(), ranges.size(), 8.0);
    ASSERT_EQ(model.beams(), 61u);
    EXPECT_EQ(model.readings(), 61u);  // every beam until a cloud is seen
    MclParams p;
    p.particles = 3000, p.threads = threads, p.resample_threshold = 0.0;  // keep the weights
    MonteCarloLocalization mcl(p, 7);
    mcl.initialize_gaussian(truth, 0.05, 0.05, 0.02);
    mcl.update(model);
    for (std::size_t b : model.used_beams()) EXPECT_TRUE(b < 25 || b >= 35) << b;
    EXPECT_GE(model.used_beams().size(), 45u);
    EXPECT_EQ(model.readings(), model.used_beams().size());
    weights.push_back(mcl.weights());
    used.push_back(model.used_beams());
  }
  EXPECT_EQ(used[0], used[1]);
  EXPECT_EQ(weights[0], weights[1]);
}
