// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include "kiseki/core/random.hpp"
#include "kiseki/models/local_map.hpp"
#include "kiseki/teach/evidence_map.hpp"
#include "kiseki/teach/map_merge.hpp"

using namespace kiseki;

namespace {

constexpr double kPi = 3.14159265358979323846;

// One scan's local map and hit mask: a fan of beams ending on a wall at x = `wall`.
struct Local {
  OccupancyGrid map;
  cv::Mat hits;
};

Local wall_scan(double wall, double spread = 0.6) {
  std::vector<double> angles;
  std::vector<float> ranges;
  for (int i = -30; i <= 30; ++i) {
    const double a = spread * i / 30.0;
    angles.push_back(a);
    ranges.push_back(static_cast<float>(wall / std::cos(a)));
  }
  LocalMapBuilder b;
  b.add_scan(Pose2(), angles.data(), ranges.data(), ranges.size(), 30.0);
  return {b.build(), b.hits()};
}

// One beam straight ahead, through where the wall would be, ending at 3.5 m.
Local stray_beam() {
  const double angle = 0.0;
  const float range = 3.5f;
  LocalMapBuilder b;
  b.add_scan(Pose2(), &angle, &range, 1, 30.0);
  return {b.build(), b.hits()};
}

std::int8_t at(const OccupancyGrid& m, double x, double y) {
  const CellIndex c = m.world_to_cell({x, y});
  return m.value(c.x, c.y);
}

}  // namespace

TEST(EvidenceMap, HitMaskHoldsTheBeamEndsOnly) {
  const Local l = wall_scan(2.0);
  // The cells of the 61 beams' ends, computed as wall_scan lays them: the laser at the origin,
  // beam a ending at its (float) range along (cos a, sin a).
  std::set<std::pair<int, int>> ends;
  for (int i = -30; i <= 30; ++i) {
    const double a = 0.6 * i / 30.0;
    const double r = static_cast<float>(2.0 / std::cos(a));
    const CellIndex c = l.map.world_to_cell({r * std::cos(a), r * std::sin(a)});
    ends.emplace(c.x, c.y);
  }
  std::set<std::pair<int, int>> hits;
  int occupied = 0;
  for (int y = 0; y < l.map.height(); ++y) {
    for (int x = 0; x < l.map.width(); ++x) {
      occupied += l.map.value(x, y) == kOccupied;
      if (l.hits.at<std::uint8_t>(y, x)) {
        hits.emplace(x, y);
        EXPECT_EQ(l.map.value(x, y), kOccupied);
      }
    }
  }
  EXPECT_EQ(hits, ends);  // the ends' cells, every one and no other
  EXPECT_GT(occupied, 5 * static_cast<int>(hits.size()));  // most occupied cells: the space behind the wall
}

TEST(EvidenceMap, OneStrayBeamErasesAWallUnderTheThesisRuleButNotByEvidence) {
  const OccupancyGrid frame(120, 120, 0.1, Pose2(-6.0, -6.0, 0.0));
  OccupancyGrid thesis = frame.clone();
  EvidenceMap evidence(frame);
  const Local wall = wall_scan(2.0), stray = stray_beam();
  for (int k = 0; k < 5; ++k) {
    merge_local_map(thesis, wall.map, Pose2());
    evidence.merge(wall.map, wall.hits, Pose2());
  }
  EXPECT_EQ(at(thesis, 2.05, 0.05), kOccupied);
  EXPECT_EQ(at(evidence.map(), 2.05, 0.05), kOccupied);
  merge_local_map(thesis, stray.map, Pose2());
  evidence.merge(stray.map, stray.hits, Pose2());
  EXPECT_EQ(at(thesis, 2.05, 0.05), kFree);               // the thesis' rule: erased
  EXPECT_EQ(at(evidence.map(), 2.05, 0.05), kOccupied);   // 5 hits outweigh 1 free
  EXPECT_EQ(evidence.hit_counts().at<std::int32_t>(evidence.map().world_to_cell({2.05, 0.05}).y,
                                                     evidence.map().world_to_cell({2.05, 0.05}).x), 5);
  // the space behind the wall: hidden only, occupied; the stray beam's free cells win there
  EXPECT_EQ(at(evidence.map(), 2.6, 0.35), kOccupied);
  EXPECT_EQ(at(evidence.map(), 3.05, 0.05), kFree);
  EXPECT_EQ(at(evidence.map(), -3.0, 0.0), kUnknown);
}

TEST(EvidenceMap, EqualsTheThesisRuleWhenEveryCellIsObservedOnce) {
  // Random single scans at poses far apart, turned by quarter turns so that every L cell lands
  // on its own M cell: no M cell is observed twice, so counting and the thesis' rule (unknown ->
  // L's value) must give the same map.
  const OccupancyGrid frame(400, 100, 0.1, Pose2(0.0, -5.0, 0.0));
  OccupancyGrid thesis = frame.clone();
  EvidenceMap evidence(frame);
  Random rng(7);
  for (int k = 0; k < 4; ++k) {
    std::vector<double> angles;
    std::vector<float> ranges;
    for (int i = 0; i < 90; ++i) {
      angles.push_back(-kPi / 2 + kPi * i / 90.0);
      ranges.push_back(static_cast<float>(rng.uniform(0.5, 5.0)));
    }
    LocalMapBuilder b;
    b.add_scan(Pose2(), angles.data(), ranges.data(), ranges.size(), 30.0);
    const Pose2 pose(5.0 + 10.0 * k, 0.0, 0.5 * kPi * k);
    merge_local_map(thesis, b.build(), pose);
    evidence.merge(b.build(), b.hits(), pose);
  }
  const OccupancyGrid e = evidence.map();
  int differ = 0;
  for (int y = 0; y < e.height(); ++y) {
    for (int x = 0; x < e.width(); ++x) differ += e.value(x, y) != thesis.value(x, y);
  }
  EXPECT_EQ(differ, 0);
}

TEST(EvidenceMap, RefusesAMaskOfAnotherSizeAndANonFinitePose) {
  EvidenceMap evidence(OccupancyGrid(10, 10, 0.1));
  const Local l = wall_scan(2.0);
  EXPECT_THROW(evidence.merge(l.map, cv::Mat(3, 3, CV_8UC1, cv::Scalar(0)), Pose2()),
               std::invalid_argument);
  EXPECT_THROW(evidence.merge(l.map, l.hits, Pose2(NAN, 0.0, 0.0)), std::invalid_argument);
}
