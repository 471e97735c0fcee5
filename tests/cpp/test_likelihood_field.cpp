// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The likelihood field against its formula at every beam end, and every faster path of its
// evaluation against the bits of the plain one.
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

namespace {

// The likelihood field's evaluation as it was before the sensor's placement was taken out of
// Pose2::compose (two calls per particle, with the map's rotation's cos and sin each time): the
// beam ends (model.used_beams, in the sensor frame, in cells) rotated in doubles, a per-beam
// bounds test in doubles (the model's is in integers on x86-64, and with AVX2 it takes four
// (then two) particles and four beams at a time), the table read, one particle and one beam at
// a time.
std::vector<double> likelihoods_one_at_a_time(const LikelihoodFieldModel& m, const OccupancyGrid& g,
                                              const std::vector<double>& end_x,
                                              const std::vector<double>& end_y,
                                              const std::vector<Pose2>& poses,
                                              int& just_below_zero) {
  const Pose2 to_grid = g.origin().inverse();
  const double inv_res = 1.0 / g.resolution();
  const double width = g.width(), height = g.height();
  std::vector<double> out;
  for (const Pose2& pose : poses) {
    const Pose2 s = to_grid.compose(pose.compose(m.params().sensor));
    const double px = s.x * inv_res, py = s.y * inv_res, c = std::cos(s.theta), sn = std::sin(s.theta);
    double sum = 0.0;
    for (std::size_t b : m.used_beams()) {
      const double gx = px + c * end_x[b] - sn * end_y[b], gy = py + sn * end_x[b] + c * end_y[b];
      const bool inside = gx >= 0.0 && gy >= 0.0 && gx < width && gy < height;
      just_below_zero += (gx > -1.0 && gx < 0.0) || (gy > -1.0 && gy < 0.0);  // truncated to 0
      sum += inside ? m.table().at<float>(static_cast<int>(gy), static_cast<int>(gx)) : m.outside();
    }
    out.push_back(m.params().combination == BeamCombination::nav2 ? std::log1p(sum) : sum);
  }
  return out;
}

}  // namespace

TEST(LikelihoodField, EveryFasterPathGivesTheBitsOfTheOldOne) {
  OccupancyGrid g = room();
  g.set_origin(Pose2(-1.0, -0.5, 0.3));
  const auto angles = scan_angles(61);
  std::vector<float> ranges(61);
  for (int i = 0; i < 61; ++i) ranges[i] = 0.3f + 0.13f * static_cast<float>(i);
  ranges[7] = ranges[9] = NAN;  // skipped: 59 beams, not a multiple of the 4 taken at a time
  Random rng(5);
  std::vector<Pose2> poses;  // some near or past the map's edges; 43 (ten fours, a pair, one)
  for (int k = 0; k < 40; ++k) poses.emplace_back(rng.uniform(-2.0, 12.0), rng.uniform(-2.0, 8.0), rng.uniform(-kPi, kPi));
  poses.emplace_back(1e-300, -0.0, 0.0);  // zeros of either sign at the sensor
  poses.emplace_back(1e30, -1e300, 1.0);  // ends beyond any integer type
  poses.emplace_back(INFINITY, 2.0, 0.5);  // NaN end points
  for (const Pose2 sensor : {Pose2(), Pose2(0.0, 0.0, 0.4), Pose2(0.2, -0.1, 0.05)}) {
    for (auto comb : {BeamCombination::product, BeamCombination::nav2}) {
      LikelihoodFieldParams p;
      p.combination = comb;
      p.sensor = sensor;
      LikelihoodFieldModel m(g, p);
      m.set_scan(angles.data(), ranges.data(), ranges.size(), 9.0);
      std::vector<double> end_x, end_y;  // every beam with a return, in the sensor frame, in cells
      for (int i = 0; i < 61; ++i) {
        if (std::isnan(ranges[i]) || !(ranges[i] < 9.0f)) continue;
        end_x.push_back(ranges[i] * std::cos(angles[i]) * (1.0 / g.resolution()));
        end_y.push_back(ranges[i] * std::sin(angles[i]) * (1.0 / g.resolution()));
      }
      ASSERT_EQ(end_x.size(), m.beams());
      int just_below_zero = 0;
      const std::vector<double> want = likelihoods_one_at_a_time(m, g, end_x, end_y, poses, just_below_zero);
      EXPECT_GT(just_below_zero, 0);  // ends in (-1, 0): off the map, though truncated to cell 0
      // Runs from each of the first four poses, ending at each of the last three: the three
      // edge cases at the end are each weighed in a four, in a pair and alone.
      for (std::size_t first = 0; first < 4; ++first) {
        for (std::size_t dropped = 0; dropped < 3; ++dropped) {
          std::vector<double> got(poses.size() - first - dropped);
          m.log_likelihoods(poses.data() + first, got.size(), got.data());
          for (std::size_t k = 0; k < got.size(); ++k) EXPECT_EQ(got[k], want[first + k]) << first << " " << k;
        }
      }
    }
  }
}
