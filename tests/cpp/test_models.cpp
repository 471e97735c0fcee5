// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "kiseki/models/local_map.hpp"
#include "kiseki/models/ray_space_observation.hpp"
#include "kiseki/models/space_observation.hpp"
#include "kiseki/sim/box_world.hpp"

using namespace kiseki;

namespace {

std::vector<double> fan(int n, double fov) {
  std::vector<double> a(n);
  for (int i = 0; i < n; ++i) a[i] = -fov / 2 + fov * i / (n - 1);
  return a;
}

// A 12 m x 6 m room at 0.1 m with a few pillars.
OccupancyGrid room() {
  OccupancyGrid g(120, 60, 0.1, Pose2(-2.0, -3.0, 0.0), kFree);
  for (int x = 0; x < 120; ++x) g.set(x, 0, kOccupied), g.set(x, 59, kOccupied);
  for (int y = 0; y < 60; ++y) g.set(0, y, kOccupied), g.set(119, y, kOccupied);
  for (int k = 0; k < 5; ++k) g.set(20 + 18 * k, 20 + 7 * k, kOccupied);
  return g;
}

PinholeCamera xtion() {
  return PinholeCamera::from_fov(160, 120, 58 * kPi / 180, 45 * kPi / 180, 0.5, 10.0);
}

// An optical frame at height z looking along robot +x.
Pose3 level_camera(double z) {
  Eigen::Matrix3d r;
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Pose3(Eigen::Vector3d(0, 0, z), Eigen::Quaterniond(r));
}

std::int8_t value_at(const OccupancyGrid& l, double x, double y) {
  const CellIndex c = l.world_to_cell({x, y});
  return l.value(c.x, c.y);
}

OccupancyGrid local_from(const OccupancyGrid& map, const Pose2& robot) {
  const auto angles = fan(541, 270.0 * kPi / 180.0);
  std::vector<double> r(angles.size());
  RayCastOptions o;
  o.max_range = 30.0;
  cast_scan(map, robot, angles.data(), angles.size(), o, r.data());
  std::vector<float> rf(r.begin(), r.end());
  LocalMapBuilder b;
  b.add_scan(Pose2(), angles.data(), rf.data(), rf.size(), 30.0);
  return b.build();
}

}  // namespace

TEST(LocalMap, WallAheadIsFreeThenOccupiedAndBehindIsOutOfView) {
  const auto angles = fan(181, kPi);
  std::vector<float> ranges(angles.size());
  for (std::size_t i = 0; i < angles.size(); ++i) {
    ranges[i] = std::abs(std::cos(angles[i])) > 1e-6 ? static_cast<float>(std::min(2.0 / std::cos(angles[i]), 30.0)) : 30.0f;
  }
  LocalMapBuilder b;
  b.add_scan(Pose2(), angles.data(), ranges.data(), ranges.size(), 30.0);
  const OccupancyGrid l = b.build();
  ASSERT_EQ(l.width(), 80);
  const auto at = [&](double x, double y) {
    const CellIndex c = l.world_to_cell({x, y});
    return l.value(c.x, c.y);
  };
  EXPECT_EQ(at(1.0, 0.05), kFree);        // between the robot and the wall at x = 2
  EXPECT_EQ(at(2.05, 0.05), kOccupied);   // the wall
  EXPECT_EQ(at(3.5, 0.05), kOccupied);    // behind it: unseen, counted occupied
  EXPECT_EQ(at(-2.0, 0.05), kUnknown);    // behind the robot: outside the 180 deg view
  EXPECT_EQ(at(0.5, 3.5), kFree);         // to the side, before the wall plane
}

TEST(LocalMap, DepthBandSeesTableTopsThatAPlaneAtLegHeightMisses) {
  Box top, leg;
  top.center = {2.0, 0.0, 0.85};
  top.half_size = {0.3, 1.0, 0.02};
  leg.center = {2.25, 0.75, 0.4};
  leg.half_size = {0.025, 0.025, 0.4};
  Box back;  // a wall behind the table: the plane's rows need something to read
  back.center = {5.0, 0.0, 1.0};
  back.half_size = {0.05, 5.0, 1.0};
  const BoxWorld world({top, leg, back});
  const auto cam = xtion();
  const Pose3 optical = level_camera(0.4);
  const cv::Mat depth = render_depth(world, optical, cam);
  LocalMapBuilder band, plane;
  band.add_depth_band(depth, cam, optical, 0.4, 1.0);
  plane.add_depth_band(depth, cam, optical, 0.39, 0.41);
  const OccupancyGrid lb = band.build(), lp = plane.build();
  const CellIndex front = lb.world_to_cell({1.75, 0.0});  // the table top's near edge
  EXPECT_EQ(lb.value(front.x, front.y), kOccupied);
  EXPECT_EQ(lp.value(front.x, front.y), kFree);  // the plane passes under the top
  const cv::Mat wrong(10, 10, CV_32FC1, cv::Scalar(1.0f));
  EXPECT_THROW(band.add_depth_band(wrong, cam, optical, 0.4, 1.0), std::invalid_argument);
}

TEST(LocalMap, ScanReadingsThatAreNoReadingAddNothing) {
  const std::vector<double> angles = {0.0, 0.5, 1.0, 1.5, -0.5};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> ranges = {0.0f, nan, inf, -inf, -1.0f};
  LocalMapBuilder b;
  b.add_scan(Pose2(), angles.data(), ranges.data(), ranges.size(), 30.0);
  const OccupancyGrid l = b.build();
  for (int y = 0; y < l.height(); ++y) {
    for (int x = 0; x < l.width(); ++x) ASSERT_EQ(l.value(x, y), kUnknown) << x << "," << y;
  }
}

// The regression of the wall-erasing column rule: a bench 0.3 m in front of the camera, under
// its 0.5 m minimum range, reads 0 in its columns; those columns must not become free rays
// through the wall behind it to the camera's maximum range.
TEST(LocalMap, ColumnsWithoutAReadingAddNoCellNotAFreeRayThroughTheWall) {
  Box bench, wall, floor;
  bench.center = {0.35, 0.0, 0.5};  // faces the camera at x = 0.3 m, 0.16 m wide
  bench.half_size = {0.05, 0.08, 0.5};
  wall.center = {3.05, 0.0, 1.25};
  wall.half_size = {0.05, 6.0, 1.25};
  floor.center = {0.0, 0.0, -0.05};
  floor.half_size = {10.0, 10.0, 0.05};
  const BoxWorld world({bench, wall, floor});
  const auto cam = xtion();
  const Pose3 optical = level_camera(0.4);
  const cv::Mat depth = render_depth(world, optical, cam);
  for (const auto& band : {std::pair{0.39, 0.41}, std::pair{0.4, 1.0}}) {
    LocalMapBuilder b;
    b.add_depth_band(depth, cam, optical, band.first, band.second);
    const OccupancyGrid l = b.build();
    // behind the bench, straight ahead: the wall at x = 3.0-3.1 and beyond it, never free
    for (double x = 0.55; x < 4.0; x += 0.1) {
      EXPECT_NE(value_at(l, x, 0.0), kFree) << "x = " << x << ", band " << band.first;
    }
    // the wall beside the bench's shadow is seen and the space before it free
    EXPECT_EQ(value_at(l, 3.05, 1.2), kOccupied);
    EXPECT_EQ(value_at(l, 2.0, 1.0), kFree);
    EXPECT_NE(value_at(l, 3.55, 1.2), kFree);  // behind the wall
  }
}

TEST(LocalMap, ReadingsOutsideThePlaneFreeItOnlyWhileTheirRaysRunInsideIt) {
  Box floor;  // nothing but the floor: the level rows read nothing within 10 m
  floor.center = {0.0, 0.0, -0.05};
  floor.half_size = {20.0, 20.0, 0.05};
  const auto cam = xtion();
  const Pose3 optical = level_camera(0.4);
  const cv::Mat depth = render_depth(BoxWorld({floor}), optical, cam);
  LocalMapBuilder plane;
  plane.add_depth_band(depth, cam, optical, 0.39, 0.41);
  const OccupancyGrid l = plane.build();
  int free = 0, occupied = 0;
  for (int y = 0; y < l.height(); ++y) {
    for (int x = 0; x < l.width(); ++x) {
      const Eigen::Vector2d c = l.cell_to_world(x, y);
      free += l.value(x, y) == kFree && c.norm() > 0.5;
      occupied += l.value(x, y) == kOccupied;
    }
  }
  // the floor rows leave the 0.39-0.41 m plane within 0.25 m of the camera
  EXPECT_EQ(free, 0);
  EXPECT_EQ(occupied, 0);
}

TEST(LocalMap, APixelReportedAsNothingWithinRangeIsFreeToMaxRange) {
  const auto cam = xtion();
  const Pose3 optical = level_camera(0.4);
  cv::Mat depth(cam.height, cam.width, CV_32FC1, cv::Scalar(0.0f));
  depth.row(59).setTo(std::numeric_limits<float>::infinity());  // REP 117: no return
  LocalMapBuilder b;
  b.add_depth_band(depth, cam, optical, 0.39, 0.41);
  const OccupancyGrid l = b.build();
  EXPECT_EQ(value_at(l, 3.85, 0.0), kFree);  // to the edge of the 8 m local map
  EXPECT_EQ(value_at(l, 3.85, 1.0), kFree);
  EXPECT_EQ(value_at(l, 1.0, 1.5), kUnknown);  // outside the 58 deg view
  depth.setTo(0.0f);
  LocalMapBuilder none;
  none.add_depth_band(depth, cam, optical, 0.4, 1.0);
  const OccupancyGrid empty = none.build();
  EXPECT_EQ(cv::countNonZero(empty.cells() != kUnknown), 0);  // all no reading: no cell
}

TEST(SpaceObservation, BitCountsEqualPlainLoopsOverTheRotatedLocalMap) {
  const OccupancyGrid map = room();
  SpaceObservationModel model(map);
  model.set_local_map(local_from(map, Pose2(3.0, 0.2, 0.4)));
  Random rng(3);
  for (int k = 0; k < 200; ++k) {
    const Pose2 p(rng.uniform(-3, 11), rng.uniform(-4, 4), rng.uniform(-kPi, kPi));
    const OccupancyGrid l = model.rotated_local_map(model.bin_of(p.theta));
    // the window cell: the one whose lower-left corner is the grid corner nearest the particle
    const Eigen::Vector2d g = map.world_to_grid({p.x, p.y});
    const CellIndex c{static_cast<int>(std::floor(g.x() + 0.5)), static_cast<int>(std::floor(g.y() + 0.5))};
    SpaceObservationCounts ref;
    for (int j = 0; j < l.height(); ++j)
      for (int i = 0; i < l.width(); ++i) {
        const int mx = c.x - l.width() / 2 + i, my = c.y - l.height() / 2 + j;
        const std::int8_t lv = l.value(i, j);
        if (lv < 0 || !map.contains(mx, my)) continue;
        const std::int8_t mv = map.value(mx, my);
        const bool m_occ = mv >= 65, m_free = mv >= 0 && mv <= 19;
        ref.map_occupied += m_occ;
        ref.map_free += m_free;
        ref.penetrating += (lv == kFree) && m_occ;
        ref.intruding += (lv == kOccupied) && m_free;
      }
    const SpaceObservationCounts got = model.counts(p);
    ASSERT_EQ(got.penetrating, ref.penetrating);
    ASSERT_EQ(got.map_occupied, ref.map_occupied);
    ASSERT_EQ(got.intruding, ref.intruding);
    ASSERT_EQ(got.map_free, ref.map_free);
  }
}

TEST(SpaceObservation, LikelihoodPeaksAtTheTruePose) {
  const OccupancyGrid map = room();
  const Pose2 truth(3.0, 0.2, 0.4);
  SpaceObservationModel model(map);
  model.set_local_map(local_from(map, truth));
  const double best = model.likelihood(truth);
  EXPECT_GT(best, 0.9);
  for (const Pose2& off : {Pose2(0.3, 0, 0), Pose2(0, 0.3, 0), Pose2(0, 0, 0.1), Pose2(-0.3, 0.2, 0)}) {
    EXPECT_LT(model.likelihood(truth.compose(off)), best);
  }
  const auto c = model.counts(truth);
  EXPECT_LT(c.penetration_ratio(), 2.0);  // percent
  SpaceObservationParams bad;
  bad.sigma_penetration = 0.0;
  EXPECT_THROW(SpaceObservationModel(map, bad), std::invalid_argument);
  SpaceObservationModel empty(map);
  EXPECT_THROW(empty.counts(truth), std::logic_error);
}

TEST(SpaceObservation, VisibilityReachesEveryCellOfAnOpenWindowAndStopsAtWalls) {
  OccupancyGrid open(200, 200, 0.1, Pose2(), kFree);
  SpaceObservationParams p;
  p.occlusion_aware = true;
  SpaceObservationModel model(open, p);
  model.set_local_map(LocalMapBuilder().build());  // 8 m: a window of 115 x 115 cells
  // The window is anchored on the cell whose lower-left corner is nearest the pose.
  const OccupancyGrid all = model.visibility(Pose2(10.02, 9.97, 0.0));
  ASSERT_EQ(all.width(), 115);
  int seen = 0;
  for (int j = 0; j < all.height(); ++j)
    for (int i = 0; i < all.width(); ++i) seen += all.value(i, j);
  EXPECT_EQ(seen, 115 * 115);  // the border segments pass through every cell

  // A closed box of walls around the centre cell (100, 100), 5 x 5 cells inside: the walls are
  // seen, nothing beyond them, nor the box's corner cells (hidden behind the walls beside them,
  // the diagonal segment is stopped at their corners); inside a wall, only that cell is seen.
  OccupancyGrid boxed = open.clone();
  for (int k = -3; k <= 3; ++k) {
    boxed.set(100 + k, 97, kOccupied), boxed.set(100 + k, 103, kOccupied);
    boxed.set(97, 100 + k, kOccupied), boxed.set(103, 100 + k, kOccupied);
  }
  SpaceObservationModel walled(boxed, p);
  walled.set_local_map(LocalMapBuilder().build());
  const OccupancyGrid box = walled.visibility(Pose2(10.0, 10.0, 0.0));
  for (int j = 0; j < box.height(); ++j)
    for (int i = 0; i < box.width(); ++i) {
      const int dx = std::abs(i - 57), dy = std::abs(j - 57);
      const bool inside = std::max(dx, dy) <= 3 && !(dx == 3 && dy == 3);
      ASSERT_EQ(box.value(i, j), inside ? 1 : 0) << i << ", " << j;
    }
  const OccupancyGrid wall = walled.visibility(Pose2(9.7, 10.0, 0.0));  // cell (97, 100)
  for (int j = 0; j < wall.height(); ++j)
    for (int i = 0; i < wall.width(); ++i) ASSERT_EQ(wall.value(i, j), i == 57 && j == 57 ? 1 : 0);
}

// A wall one cell thick at x in [5.0, 5.1) across a 10 m x 4 m floor; the robot at (1.05,
// 2.05) looks along +x with one beam, max range 10 m: the wall is 3.95 m ahead.
TEST(RaySpaceObservation, OneBeamIsTheMixtureByHand) {
  OccupancyGrid g(100, 40, 0.1, Pose2(), kFree);
  for (int y = 0; y < 40; ++y) g.set(50, y, kOccupied);
  RaySpaceObservationModel model(g);
  const RaySpaceObservationParams& p = model.params();
  const double angle = 0.0, max_range = 10.0;
  const Pose2 robot(1.05, 2.05, 0.0);
  auto gauss = [&](double h) {
    return p.z_hit * std::exp(-h * h / (2 * p.sigma_hit * p.sigma_hit)) / (std::sqrt(2 * kPi) * p.sigma_hit);
  };
  double out = 0.0;
  // Stopped 2 m short of the wall (an intrusion): the end is 2.0 m from the wall's cell
  // centre (capped at max_distance 2.0), and the intrusion term applies.
  const float short_reading = 2.0f;
  model.set_scan(&angle, &short_reading, 1, max_range);
  model.log_likelihoods(&robot, 1, &out);
  EXPECT_NEAR(out, std::log(gauss(2.0) + p.z_intrusion * p.lambda_short * std::exp(-p.lambda_short * 2.0) +
                            p.z_rand / max_range), 1e-9);
  // Through the wall (a penetration): no intrusion term, and scored by the depth past the
  // wall's face 3.95 m away (0.55 m), which exceeds the end's distance to the wall's centre
  // (0.5 m: the end's cell centre at 5.55, the wall's at 5.05).
  const float long_reading = 4.5f;
  model.set_scan(&angle, &long_reading, 1, max_range);
  model.log_likelihoods(&robot, 1, &out);
  EXPECT_NEAR(out, std::log(gauss(0.55) + p.z_rand / max_range), 1e-9);
  // A no-return is skipped: nothing to weigh.
  const float none = std::numeric_limits<float>::infinity();
  model.set_scan(&angle, &none, 1, max_range);
  model.log_likelihoods(&robot, 1, &out);
  EXPECT_EQ(out, 0.0);
  EXPECT_EQ(model.readings(), 0u);
}

// The same wall; three beams along +x: one ends on the wall's face (agrees), one stops 2 m
// short in the open (an intrusion), one passes through the wall (disagrees). The plain
// agreement counts the intrusion against the pose (1 of 3); the intrusion-tolerant one leaves
// it out (1 of 2), and has nothing to go by when every beam is an intrusion; a place a reset
// proposes is judged by the plain one in both.
TEST(RaySpaceObservation, IntrusionTolerantAgreementLeavesOutBeamsEndingInTheOpen) {
  OccupancyGrid g(100, 40, 0.1, Pose2(), kFree);
  for (int y = 0; y < 40; ++y) g.set(50, y, kOccupied);
  RaySpaceObservationParams tolerant;
  tolerant.agreement_skips_intrusion = true;
  RaySpaceObservationModel plain_model(g), tolerant_model(g, tolerant);
  const double angles[3] = {0.0, 0.0, 0.0}, max_range = 10.0;
  const float ranges[3] = {3.95f, 2.0f, 4.5f};
  const Pose2 robot(1.05, 2.05, 0.0);
  plain_model.set_scan(angles, ranges, 3, max_range);
  tolerant_model.set_scan(angles, ranges, 3, max_range);
  EXPECT_DOUBLE_EQ(plain_model.agreement(robot), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(tolerant_model.agreement(robot), 1.0 / 2.0);
  // A reset's proposed place is judged with every beam, whichever measure judges being lost.
  EXPECT_DOUBLE_EQ(tolerant_model.placement_agreement(robot), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(plain_model.placement_agreement(robot), 1.0 / 3.0);
  // The likelihood is the same model's: the switch changes the agreement only.
  double a = 0.0, b = 1.0;
  plain_model.log_likelihoods(&robot, 1, &a);
  tolerant_model.log_likelihoods(&robot, 1, &b);
  EXPECT_EQ(a, b);
  const float open[2] = {1.0f, 2.0f};
  plain_model.set_scan(angles, open, 2, max_range);
  tolerant_model.set_scan(angles, open, 2, max_range);
  EXPECT_EQ(plain_model.agreement(robot), 0.0);
  EXPECT_TRUE(std::isnan(tolerant_model.agreement(robot)));
}
