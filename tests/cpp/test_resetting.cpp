// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// Resetting on a likelihood seen alone: a drop in the likelihood resets a cloud carried to a place
// that looks alike, a flat likelihood needs evidence, the look-elsewhere term, and the sensor
// reset proposal's shares and spread.
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

// A measurement seen only through its likelihood: log p = -|pose - target|^2 / (2 0.3^2) (position
// in m and heading in rad alike) plus `ripple` sin(3x) cos(2y), over 30 readings, with a fixed
// agreement with the map (agree_near within near_radius of near, agree elsewhere); a proposed
// place is judged by the same agreement, or by place_near within near_radius when it is set.
class TargetModel : public SensorModel {
 public:
  Pose2 target;
  double peak = 1.0;  ///< 0: a flat likelihood (the ripple only)
  double ripple = 0.0;
  double agree = 1.0;
  Pose2 near;
  double near_radius = 0.0;  ///< 0: the same agreement everywhere
  double agree_near = 1.0;
  double place_near = std::numeric_limits<double>::quiet_NaN();
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override {
    for (std::size_t i = 0; i < n; ++i) {
      const Pose2& q = poses[i];
      const double d2 = std::pow(q.x - target.x, 2) + std::pow(q.y - target.y, 2) +
                        std::pow(angle_difference(q.theta, target.theta), 2);
      out[i] = -0.5 * peak * d2 / 0.09 + ripple * std::sin(3 * q.x) * std::cos(2 * q.y);
    }
  }
  std::size_t readings() const override { return 30; }
  double agreement(const Pose2& q) const override {
    return std::hypot(q.x - near.x, q.y - near.y) < near_radius ? agree_near : agree;
  }
  double placement_agreement(const Pose2& q) const override {
    if (std::isnan(place_near)) return agreement(q);
    return std::hypot(q.x - near.x, q.y - near.y) < near_radius ? place_near : agree;
  }
};

TEST(MonteCarloLocalization, ALikelihoodDropResetsACloudCarriedToAPlaceThatLooksAlike) {
  // The scans go on agreeing with the map (agreement 1), or the model cannot tell (NaN), but
  // the robot is elsewhere: only the likelihood has dropped against its long-term average. A
  // drop of 0 turns that trigger off in both.
  for (const double agree : {1.0, std::numeric_limits<double>::quiet_NaN()}) {
    for (const double drop : {0.0, 0.5}) {
      SCOPED_TRACE(agree);
      SCOPED_TRACE(drop);
      MclParams p;
      p.particles = 1000;
      p.recovery = Recovery::resetting;
      p.reset_likelihood_drop = drop;
      MonteCarloLocalization mcl(p, 11);
      mcl.set_free_space(room());
      TargetModel model;
      model.agree = agree;
      model.target = Pose2(1.0, 4.5, 0.0);
      mcl.initialize_gaussian(model.target, 0.1, 0.1, 0.05);
      for (int k = 0; k < 20; ++k) mcl.update(model);
      model.target = Pose2(7.5, 1.0, 2.0);
      int sensor_resets = 0;
      for (int k = 0; k < 30; ++k) sensor_resets += mcl.update(model).reset == "sensor";
      if (drop == 0.0) {
        EXPECT_EQ(sensor_resets, 0);
        EXPECT_GT(position_error(mcl.estimate(), model.target), 3.0);  // agreement alone cannot see it
      } else {
        EXPECT_GE(sensor_resets, 1);
        EXPECT_LT(position_error(mcl.estimate(), model.target), 0.3);
      }
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
    p.reset_needs_agreement = false;  // the likelihood's margin alone (the map agrees nowhere)
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
      EXPECT_LT(position_error(mcl.estimate(), start), 0.5);  // the ripple alone moves it a little
    } else {
      EXPECT_GT(resets, 0);
      EXPECT_GT(position_error(mcl.estimate(), start), 1.0);
    }
  }
  MclParams bad;
  bad.reset_evidence = -1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = MclParams{};
  bad.reset_likelihood_drop = 1.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(MonteCarloLocalization, TheLookElsewhereTermAsksForLnNMoreOfTheBestOfNCandidates) {
  // One particle 1.04 m from the target: the cloud's best log-likelihood is -6.0 (d^2 / (2
  // 0.3^2)); the best of 20,000 uniform candidates in the 10 m x 6 m room lies within about
  // 0.2 m of the target (-0.2 or better), so it beats the cloud by about 6 nats: more than ln 10
  // (2.3), less than ln 10 + ln 20,000 (12.2). Without the term the sensor reset is kept, with
  // it not; the expansion (radius 0) never explains better.
  EXPECT_DOUBLE_EQ(look_elsewhere_term(20000.0), std::log(20000.0));
  EXPECT_DOUBLE_EQ(look_elsewhere_term(0.5), 0.0);
  for (const bool look : {false, true}) {
    MclParams p;
    p.particles = 1;
    p.recovery = Recovery::resetting;
    p.reset_after = p.sensor_reset_after = 1;
    p.expansion_position = p.expansion_orientation = 0.0;
    p.reset_look_elsewhere = look;
    p.reset_needs_agreement = p.sensor_reset_confirm = false;  // the likelihood's test alone
    MonteCarloLocalization mcl(p, 21);
    mcl.set_free_space(room());
    TargetModel model;
    model.target = Pose2(4.0, 3.0, 0.5);
    model.agree = 0.0;  // every scan disagrees: lost at once
    mcl.set_particles({Pose2(4.0 + 1.04, 3.0, 0.5)});
    EXPECT_EQ(mcl.update(model).reset, look ? "none" : "sensor");
    EXPECT_EQ(position_error(mcl.estimate(), model.target) < 0.5, !look);
  }
}

TEST(MonteCarloLocalization, AResetNeverMovesTheCloudWhereTheMapAgreesLessThanWhereItIs) {
  // The cloud tracks A, where the map agrees with 80 % of the beams; then the likelihood moves
  // to B (the drop trigger). A sensor reset to B is made only if the map agrees there at least
  // as well as at A and at least reset_threshold (0.6); without the check it is made always.
  // A model that judges a proposed place by another measure than agreement() (the ray model's
  // plain agreement beside its intrusion-tolerant one) is judged by that one (place_b).
  const Pose2 a(1.0, 4.5, 0.0), b(7.5, 1.0, 2.0);
  const double same = std::numeric_limits<double>::quiet_NaN();  // place_b: agreement() itself
  struct Case {
    double agree_b;
    bool check;
    bool moves;
    double place_b;
  };
  for (const Case c : {Case{0.9, true, true, same}, Case{0.7, true, false, same},
                       Case{0.3, true, false, same}, Case{0.3, false, true, same},
                       Case{0.9, true, false, 0.3}, Case{0.3, true, true, 0.9}}) {
    MclParams p;
    p.particles = 1000;
    p.recovery = Recovery::resetting;
    p.reset_needs_agreement = c.check;
    p.expansion_position = p.expansion_orientation = 0.0;  // only a sensor reset can move it
    MonteCarloLocalization mcl(p, 31);
    mcl.set_free_space(room());
    TargetModel model;
    model.target = a;
    model.agree = 0.8;
    model.near = b;
    model.near_radius = 1.0;
    model.agree_near = c.agree_b;
    model.place_near = c.place_b;
    mcl.initialize_gaussian(a, 0.1, 0.1, 0.05);
    for (int k = 0; k < 20; ++k) mcl.update(model);
    model.target = b;
    int sensor_resets = 0;
    for (int k = 0; k < 30; ++k) sensor_resets += mcl.update(model).reset == "sensor";
    SCOPED_TRACE(c.agree_b);
    SCOPED_TRACE(c.check);
    SCOPED_TRACE(c.place_b);
    if (c.moves) {
      EXPECT_GE(sensor_resets, 1);
      EXPECT_LT(position_error(mcl.estimate(), b), 0.3);
    } else {
      EXPECT_EQ(sensor_resets, 0);
      EXPECT_LT(position_error(mcl.estimate(), a), 0.5);
    }
  }
}

TEST(MonteCarloLocalization, ASensorResetIsMadeOnlyWhenTheNextScanConfirmsIt) {
  // Reset on the first lost update. One odd scan fits B (the map disagrees everywhere else):
  // without confirmation the cloud jumps to B; with it, the next scan fits A again and the
  // held reset is dropped. A robot really carried to B is found one update later.
  const Pose2 a(1.0, 4.5, 0.0), b(7.5, 1.0, 2.0);
  for (const bool confirm : {false, true}) {
    SCOPED_TRACE(confirm);
    MclParams p;
    p.particles = 1000;
    p.recovery = Recovery::resetting;
    p.reset_after = p.sensor_reset_after = 1;
    p.sensor_reset_confirm = confirm;
    MonteCarloLocalization mcl(p, 32);
    mcl.set_free_space(room());
    TargetModel model;
    model.near = b;
    model.near_radius = 1.0;
    const auto fit = [&](const Pose2& where, double agree_elsewhere) {
      model.target = where;
      model.agree = agree_elsewhere;
    };
    fit(a, 1.0);
    mcl.initialize_gaussian(a, 0.1, 0.1, 0.05);
    for (int k = 0; k < 20; ++k) mcl.update(model);
    fit(b, 0.0);  // the odd scan
    EXPECT_EQ(mcl.update(model).reset, confirm ? "none" : "sensor");
    EXPECT_LT(position_error(mcl.estimate(), confirm ? a : b), 0.5);
    if (confirm) {
      fit(a, 1.0);
      EXPECT_EQ(mcl.update(model).reset, "none");
      EXPECT_LT(position_error(mcl.estimate(), a), 0.5);
    }

    fit(a, 1.0);
    mcl.initialize_gaussian(a, 0.1, 0.1, 0.05);
    for (int k = 0; k < 20; ++k) mcl.update(model);
    fit(b, 0.0);  // carried to B for good
    EXPECT_EQ(mcl.update(model).reset, confirm ? "none" : "sensor");
    if (confirm) {
      EXPECT_EQ(mcl.update(model).reset, "sensor");
    }
    EXPECT_LT(position_error(mcl.estimate(), b), 0.5);
  }
}

TEST(SensorResetProposal, PosesAroundHypothesesTakeTheirSharesByTemperedScoreAndTheStatedSpread) {
  // scores 0, -ln 3 and -40 at power 1: shares 3 : 1 : 4e-18 of 4,000 poses, 3,000 and 1,000
  std::vector<PoseHypothesis> found(3);
  found[0].pose = Pose2(1.0, 2.0, 3.0);
  found[1].pose = Pose2(5.0, -1.0, -1.0);
  found[2].pose = Pose2(-4.0, 0.0, 0.0);
  found[0].score = 0.0, found[1].score = -std::log(3.0), found[2].score = -40.0;
  Random rng(5);
  const std::vector<Pose2> out = poses_around_hypotheses(found, 4000, 0.05, 0.02, 1.0, rng);
  ASSERT_EQ(out.size(), 4000u);
  for (std::size_t h = 0; h < 2; ++h) {
    const std::size_t begin = h == 0 ? 0 : 3000, end = h == 0 ? 3000 : 4000;
    double mx = 0, sx = 0, st = 0;
    for (std::size_t i = begin; i < end; ++i) mx += out[i].x;
    mx /= static_cast<double>(end - begin);
    for (std::size_t i = begin; i < end; ++i) {
      sx += std::pow(out[i].x - mx, 2);
      st += std::pow(angle_difference(out[i].theta, found[h].pose.theta), 2);
      EXPECT_LT(std::hypot(out[i].x - found[h].pose.x, out[i].y - found[h].pose.y), 0.05 * 6);
    }
    EXPECT_NEAR(mx, found[h].pose.x, 4 * 0.05 / std::sqrt(static_cast<double>(end - begin)));
    EXPECT_NEAR(std::sqrt(sx / static_cast<double>(end - begin)), 0.05, 0.005);
    EXPECT_NEAR(std::sqrt(st / static_cast<double>(end - begin)), 0.02, 0.002);
  }
  // a heading near pi stays in [-pi, pi); no hypothesis or a negative spread is refused
  found[0].pose.theta = kPi - 1e-3;
  for (const Pose2& q : poses_around_hypotheses(found, 500, 0.0, 0.05, 1.0, rng)) {
    EXPECT_GE(q.theta, -kPi);
    EXPECT_LT(q.theta, kPi);
  }
  EXPECT_THROW(poses_around_hypotheses({}, 10, 0.1, 0.1, 1.0, rng), std::invalid_argument);
  EXPECT_THROW(poses_around_hypotheses(found, 10, -0.1, 0.1, 1.0, rng), std::invalid_argument);
  EXPECT_THROW(reset_proposal_from_name("grid"), std::invalid_argument);
  // the matcher proposal refuses an update without the scan, or without a matcher
  MclParams p;
  p.recovery = Recovery::resetting;
  p.sensor_reset_proposal = ResetProposal::matcher;
  MonteCarloLocalization mcl(p, 1);
  mcl.set_particles({Pose2(1.0, 1.0, 0.0)});
  TargetModel model;
  EXPECT_THROW(mcl.update(model), std::logic_error);
  EXPECT_THROW(mcl.update(model, ScanView{}), std::logic_error);
  for (const int every : {0, 1001}) {
    p.matcher_search_every = every;
    EXPECT_THROW(p.validate(), std::invalid_argument);
  }
}

}  // namespace
