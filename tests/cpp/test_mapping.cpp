// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kiseki/core/angle.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "kiseki/mapping/log_odds_mapper.hpp"

using namespace kiseki;

namespace {

// A closed 6 m x 4 m room drawn into a grid, 0.05 m cells.
OccupancyGrid room() {
  OccupancyGrid g(120, 80, 0.05, Pose2(), kFree);
  for (int x = 0; x < 120; ++x) g.set(x, 0, kOccupied), g.set(x, 79, kOccupied);
  for (int y = 0; y < 80; ++y) g.set(0, y, kOccupied), g.set(119, y, kOccupied);
  return g;
}

}  // namespace

TEST(LogOddsMapper, RebuildsARoomFromItsOwnSimulatedScans) {
  const OccupancyGrid truth = room();
  std::vector<double> angles(181);
  for (int i = 0; i < 181; ++i) angles[i] = -kPi / 2 + i * kPi / 180;
  std::vector<double> poses;
  std::vector<float> ranges;
  RayCastOptions o;
  o.max_range = 8.0;
  for (int k = 0; k < 40; ++k) {
    const Pose2 p(1.0 + 0.1 * k, 1.0 + 0.05 * k, 0.16 * k);
    std::vector<double> r(angles.size());
    cast_scan(truth, p, angles.data(), angles.size(), o, r.data());
    poses.insert(poses.end(), {p.x, p.y, p.theta});
    ranges.insert(ranges.end(), r.begin(), r.end());
  }
  LogOddsParams params;
  params.max_range = 8.0;
  params.usable_range = 8.0;
  const auto b = LogOddsMapper::scan_bounds(poses.data(), ranges.data(), angles.data(), 40,
                                            angles.size(), params);
  EXPECT_NEAR(b[0], 0.0, 0.06);
  EXPECT_NEAR(b[2], 6.0 - 0.05, 0.06);
  LogOddsMapper mapper(b[0], b[1], b[2], b[3], params);
  for (int k = 0; k < 40; ++k) {
    mapper.integrate_scan(Pose2(poses[3 * k], poses[3 * k + 1], poses[3 * k + 2]),
                          &ranges[k * angles.size()], angles.data(), angles.size());
  }
  const OccupancyGrid map = mapper.to_occupancy();
  const auto [hits, endpoints] = endpoint_agreement(map, poses.data(), ranges.data(),
                                                    angles.data(), 40, angles.size(), 8.0, 1);
  EXPECT_EQ(endpoints, 40u * 181u);
  EXPECT_GT(static_cast<double>(hits) / endpoints, 0.99);
  // The room's interior around the robot's path is free.
  const CellIndex c = map.world_to_cell({2.5, 2.0});
  EXPECT_EQ(map.value(c.x, c.y), kFree);
  // Strictly with no neighbourhood the agreement can only fall.
  const auto strict = endpoint_agreement(map, poses.data(), ranges.data(), angles.data(), 40,
                                         angles.size(), 8.0, 0);
  EXPECT_LE(strict.first, hits);
}

TEST(LogOddsMapper, OneCellUpdatedOncePerScanAndHitsWinOverMisses) {
  LogOddsParams params;
  params.resolution = 1.0;
  LogOddsMapper mapper(0, 0, 10, 10, params);
  const std::vector<double> angles = {0.0, 0.0, 0.0};
  const std::vector<float> ranges = {5.0, 5.0, 3.0};  // ends in cells 5, 5, 3
  mapper.integrate_scan(Pose2(0.5, 0.5, 0.0), ranges.data(), angles.data(), 3);
  const float l_hit = std::log(0.7f / 0.3f), l_miss = std::log(0.4f / 0.6f);
  EXPECT_NEAR(mapper.log_odds().at<float>(0, 5), l_hit, 1e-6);  // hit once, not twice
  EXPECT_NEAR(mapper.log_odds().at<float>(0, 3), l_hit, 1e-6);  // hit by beam 3, not missed by 1
  EXPECT_NEAR(mapper.log_odds().at<float>(0, 1), l_miss, 1e-6);  // missed once, not three times
  EXPECT_EQ(mapper.log_odds().at<float>(1, 1), 0.0f);
  params.prob_hit = 0.4;
  EXPECT_THROW(LogOddsMapper(0, 0, 1, 1, params), std::invalid_argument);
}
