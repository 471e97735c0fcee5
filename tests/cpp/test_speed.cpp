// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "kiseki/core/angle.hpp"
#include "kiseki/grid/ray_casting.hpp"
#include "kiseki/speed/speed_reference.hpp"

namespace kiseki {
namespace {

struct Scan {
  std::vector<double> angles;
  std::vector<float> ranges;
  double max_range = 4.0;
  PlanarScan view() const { return {angles.data(), ranges.data(), angles.size(), max_range}; }
};

/// The paper's laser: 683 beams over +-120 deg, 4 m, cast in `world`.
Scan cast(const OccupancyGrid& world, const Pose2& sensor) {
  Scan s;
  for (int i = 0; i < 683; ++i) s.angles.push_back(-2 * kPi / 3 + i * (4 * kPi / 3) / 682);
  std::vector<double> out(s.angles.size());
  RayCastOptions o;
  o.max_range = s.max_range;
  cast_scan(world, sensor, s.angles.data(), s.angles.size(), o, out.data());
  for (double r : out) s.ranges.push_back(static_cast<float>(r));
  return s;
}

OccupancyGrid free_field() { return OccupancyGrid(240, 240, 0.05, Pose2(-6.0, -6.0, 0.0), kFree); }

TEST(OcclusionRatio, OpenFieldIsFullySeen) {
  const OccupancyGrid map = free_field();
  const Pose2 sensor(0.0, 0.0, kPi / 2);
  const Scan s = cast(map, sensor);
  const OcclusionRatio r = occlusion_ratio(map, sensor, s.view(), sensor.theta, {});
  EXPECT_DOUBLE_EQ(r.ratio, 1.0);
  // the half disc of 4 m in 0.05 m cells: pi 80^2 / 2 = 10053 cells
  EXPECT_NEAR(static_cast<double>(r.free_cells), kPi * 80 * 80 / 2, 80.0);
}

TEST(OcclusionRatio, KnownWallAheadHidesWhatLiesBehindIt) {
  // A wall (one cell thick, across the whole map) whose near face is d ahead of the sensor;
  // free space behind it counts in the region but cannot be seen. Expected ratio: the part of
  // the half disc of radius R nearer than d,  (d sqrt(R^2 - d^2) + R^2 asin(d / R)) / (pi R^2 / 2).
  for (double d : {1.0, 2.0, 3.0}) {
    OccupancyGrid map = free_field();
    const int row = static_cast<int>(std::lround((d + 6.0) / 0.05));  // cell whose lower edge is at y = d
    for (int x = 0; x < map.width(); ++x) map.set(x, row, kOccupied);
    const Pose2 sensor(0.0, 0.0, kPi / 2);
    const Scan s = cast(map, sensor);
    const double R = 4.0;
    const double expected = (d * std::sqrt(R * R - d * d) + R * R * std::asin(d / R)) / (kPi * R * R / 2);
    const OcclusionRatio r = occlusion_ratio(map, sensor, s.view(), sensor.theta, {});
    EXPECT_NEAR(r.ratio, expected, 0.02) << "d = " << d;
  }
}

TEST(OcclusionRatio, UnknownObstacleShrinksTheRatioAndNaNIsUnseen) {
  const OccupancyGrid map = free_field();
  OccupancyGrid world = map.clone();
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) world.set(116 + x, 150 + y, kOccupied);  // 0.4 m box 1.5 m ahead
  const Pose2 sensor(0.0, 0.0, kPi / 2);
  Scan s = cast(world, sensor);
  const OcclusionRatio with_box = occlusion_ratio(map, sensor, s.view(), sensor.theta, {});
  EXPECT_LT(with_box.ratio, 0.99);
  EXPECT_GT(with_box.ratio, 0.9);
  // The box's shadow: between the box's near face (1.5 m) and 4 m, over the box's angular width
  // (2 atan(0.2 / 1.5)): about (4^2 - 1.5^2) / 2 * 0.265 rad = 1.82 m^2 of the 25.1 m^2 half disc.
  EXPECT_NEAR(1.0 - with_box.ratio, 1.82 / (kPi * 16 / 2), 0.012);
  for (auto& r : s.ranges) r = std::numeric_limits<float>::quiet_NaN();
  EXPECT_DOUBLE_EQ(occlusion_ratio(map, sensor, s.view(), sensor.theta, {}).ratio, 0.0);
}

TEST(OcclusionRatio, LabelsCountWhatTheRatioCounts) {
  OccupancyGrid map = free_field();
  for (int x = 0; x < map.width(); ++x) map.set(x, 160, kOccupied);  // 2 m ahead
  const Pose2 sensor(0.3, -0.2, kPi / 3);
  const Scan s = cast(map, sensor);
  cv::Mat labels;
  const OcclusionRatio r = occlusion_ratio(map, sensor, s.view(), kPi / 2, {}, &labels);
  ASSERT_EQ(labels.rows, map.height());
  EXPECT_EQ(static_cast<std::size_t>(cv::countNonZero(labels == 2)), r.seen_cells);
  EXPECT_EQ(static_cast<std::size_t>(cv::countNonZero(labels)), r.free_cells);
  EXPECT_EQ(labels.at<std::uint8_t>(160, 120), 0);  // the wall is not free
  EXPECT_EQ(labels.at<std::uint8_t>(170, 126), 1);  // behind it: free, unseen
  EXPECT_EQ(labels.at<std::uint8_t>(140, 126), 2);  // before it: seen
}

TEST(OcclusionRatio, HeadingBeyondTheFieldOfViewIsUnseen) {
  const OccupancyGrid map = free_field();
  const Pose2 sensor(0.0, 0.0, 0.0);
  const Scan s = cast(map, sensor);
  // moving backwards: +-90 deg around pi, the laser sees +-120 deg around 0 -> the two 30 deg
  // wedges between 90 and 120 deg on each side are seen: 60 / 180 of the half disc
  const OcclusionRatio r = occlusion_ratio(map, sensor, s.view(), kPi, {});
  EXPECT_NEAR(r.ratio, 60.0 / 180.0, 0.01);
}

TEST(OcclusionRatio, MapWithoutFreeCellsGivesOne) {
  const OccupancyGrid map(50, 50, 0.05, Pose2(-1.25, -1.25, 0.0), kUnknown);
  const Scan s = cast(free_field(), Pose2());
  EXPECT_DOUBLE_EQ(occlusion_ratio(map, Pose2(), s.view(), 0.0, {}).ratio, 1.0);
}

TEST(OcclusionRatio, BadInputIsRefused) {
  const OccupancyGrid map = free_field();
  Scan s = cast(map, Pose2());
  OcclusionRatioOptions o;
  o.half_angle = 0.0;
  EXPECT_THROW(occlusion_ratio(map, Pose2(), s.view(), 0.0, o), std::invalid_argument);
  o.half_angle = kPi + 0.01;
  EXPECT_THROW(occlusion_ratio(map, Pose2(), s.view(), 0.0, o), std::invalid_argument);
  Scan empty;
  EXPECT_THROW(occlusion_ratio(map, Pose2(), empty.view(), 0.0, {}), std::invalid_argument);
  std::swap(s.angles[0], s.angles[1]);
  EXPECT_THROW(occlusion_ratio(map, Pose2(), s.view(), 0.0, {}), std::invalid_argument);
}

/// The paper's laser (683 beams over +-120 deg, 4 m) at the origin looking along +x in a
/// corridor along x with walls at y = +left and y = -right and, when ahead > 0, an end wall
/// across it at x = ahead: exact ranges (ray against the three lines).
Scan corridor(double left, double right, double ahead) {
  Scan s;
  for (int i = 0; i < 683; ++i) s.angles.push_back(-2 * kPi / 3 + i * (4 * kPi / 3) / 682);
  for (double a : s.angles) {
    const double sn = std::sin(a), cs = std::cos(a);
    double r = s.max_range;
    if (sn > 1e-9) r = std::min(r, left / sn);
    if (sn < -1e-9) r = std::min(r, -right / sn);
    if (ahead > 0 && cs > 1e-9) r = std::min(r, ahead / cs);
    s.ranges.push_back(static_cast<float>(r));
  }
  return s;
}

TEST(PassageWidth, CorridorWallsGiveTheClearWidth) {
  // walls at y = +0.8 and y = -0.7 of a sensor looking along +x: eq. 2's w = 1.5 m
  const Scan s = corridor(0.8, 0.7, 0.0);
  const PassageWidth w = passage_width(s.view(), 0.0, 0.05);
  EXPECT_NEAR(w.left, 0.8, 1e-5);
  EXPECT_NEAR(w.right, 0.7, 1e-5);
  EXPECT_NEAR(w.width, 1.5, 1e-5);
  // heading across the corridor (+y): the line across that heading is the corridor's axis,
  // which no wall crosses within the range: both sides are open
  EXPECT_DOUBLE_EQ(passage_width(s.view(), kPi / 2, 0.05).width, 2 * s.max_range);
}

TEST(PassageWidth, AWallAheadIsNotASideOfThePassage) {
  // w is measured across the heading (eq. 2, Fig. 3a): a straight corridor of width W gives
  // w = W whatever wall closes it ahead, wherever the robot stands across it, with the default
  // parameters of eq. 4. The first case is the 2.3 m corridor of the paper's situation 1 with a
  // wall 0.9 m ahead (w = 2.3 m; counting the wall's points straight ahead as sides gave 0.006 m
  // and f(w) = 0.0018).
  SpeedReferenceParams params;  // the paper's sec. 4 values
  params.use_occlusion = false;
  const OccupancyGrid map = free_field();
  for (double width : {2.3, 1.5, 0.9}) {
    for (double offset : {0.0, 0.2, -0.3}) {
      for (double ahead : {0.9, 0.3, 1.5, 3.0}) {
        const double left = width / 2 - offset, right = width / 2 + offset;
        const Scan s = corridor(left, right, ahead);
        const SpeedReference r = speed_reference(map, Pose2(), s.view(), 0.0, params);
        EXPECT_NEAR(r.passage.width, width, 1e-5) << "W " << width << ", offset " << offset << ", wall " << ahead;
        EXPECT_NEAR(r.passage.left, left, 1e-5);
        EXPECT_NEAR(r.passage.right, right, 1e-5);
        const double f = 1.0 / (1.0 + std::exp(-4.9 * (width - 1.3)));  // eq. 3
        EXPECT_NEAR(r.v_ref, 0.5 * f, 1e-5);                             // eq. 2
      }
    }
  }
  EXPECT_THROW(passage_width(corridor(1.0, 1.0, 0.0).view(), 0.0, 0.0), std::invalid_argument);
}

TEST(WidthFactor, SigmoidAtTheParametersOfThePaper) {
  const double w1 = 0.70, w2 = 2.0, a = 4.9, b = w2 - w1;
  EXPECT_DOUBLE_EQ(width_factor(b, w1, w2, a), 0.5);
  EXPECT_NEAR(width_factor(w1, w1, w2, a), 1.0 / (1.0 + std::exp(4.9 * 0.6)), 1e-15);
  EXPECT_NEAR(width_factor(w2, w1, w2, a), 1.0 / (1.0 + std::exp(-4.9 * 0.7)), 1e-15);
  EXPECT_NEAR(width_factor(1.5, w1, w2, a), 0.7271, 1e-4);  // the 1.5 m corridor of situation 3
  EXPECT_NEAR(width_factor(1e6, w1, w2, a), 1.0, 1e-15);
  EXPECT_THROW(width_factor(1.0, 2.0, 2.0, a), std::invalid_argument);
  EXPECT_THROW(width_factor(1.0, 2.0, 1.0, a), std::invalid_argument);
  EXPECT_THROW(width_factor(1.0, w1, w2, 0.0), std::invalid_argument);
}

TEST(SpeedReference, ProductOfTheTwoFactors) {
  OccupancyGrid map = free_field();
  for (int x = 0; x < map.width(); ++x) map.set(x, static_cast<int>(std::lround(8.0 / 0.05)), kOccupied);
  const Pose2 sensor(0.0, 0.0, kPi / 2);
  const Scan s = cast(map, sensor);
  SpeedReferenceParams p;
  const SpeedReference both = speed_reference(map, sensor, s.view(), sensor.theta, p);
  EXPECT_NEAR(both.v_ref, 0.5 * both.occlusion.ratio * both.width_factor, 1e-12);
  p.use_width = false;
  EXPECT_NEAR(speed_reference(map, sensor, s.view(), sensor.theta, p).v_ref, 0.5 * both.occlusion.ratio, 1e-12);
  p.use_occlusion = false;
  EXPECT_DOUBLE_EQ(speed_reference(map, sensor, s.view(), sensor.theta, p).v_ref, 0.5);
  p.w2 = p.w1;
  EXPECT_THROW(speed_reference(map, sensor, s.view(), sensor.theta, p), std::invalid_argument);
}

}  // namespace
}  // namespace kiseki
