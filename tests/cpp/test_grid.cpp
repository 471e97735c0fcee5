// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/grid/distance_field.hpp"
#include "kiseki/grid/local_window.hpp"
#include "kiseki/grid/map_image.hpp"
#include "kiseki/io/image_file.hpp"
#include "kiseki/grid/ray_casting.hpp"

using namespace kiseki;

namespace {

OccupancyGrid random_grid(std::uint64_t seed, double p_occupied, const Pose2& origin) {
  OccupancyGrid g(40, 30, 0.1, origin, kFree);
  Random r(seed);
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x)
      if (r.uniform() < p_occupied) g.set(x, y, kOccupied);
  return g;
}

// Reference ray cast, independent of the traversal: intersect the ray with every obstacle
// cell as an axis-aligned box in grid coordinates (slab test) and keep the nearest entry.
double brute_force_range(const OccupancyGrid& g, Eigen::Vector2d s, double heading, double max) {
  const Eigen::Vector2d p = g.world_to_grid(s);
  const double a = heading - g.origin().theta;
  const Eigen::Vector2d d(std::cos(a), std::sin(a));
  double best = max / g.resolution();
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      if (g.value(x, y) < 65) continue;
      double t0 = 0.0, t1 = best;
      const double lo[2] = {double(x), double(y)};
      bool miss = false;
      for (int k = 0; k < 2 && !miss; ++k) {
        if (d[k] == 0.0) {
          miss = p[k] < lo[k] || p[k] >= lo[k] + 1.0;
          continue;
        }
        double ta = (lo[k] - p[k]) / d[k], tb = (lo[k] + 1.0 - p[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (!miss && t0 <= t1) best = std::min(best, t0);
    }
  }
  return best * g.resolution();
}

}  // namespace

TEST(OccupancyGrid, CellValuesOutsideTheRosRangeAreRefused) {
  EXPECT_THROW(OccupancyGrid(3, 3, 0.1, Pose2(), 120), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(3, 3, 0.1, Pose2(), -2), std::invalid_argument);
  OccupancyGrid g(3, 3, 0.1, Pose2(), kFree);
  EXPECT_THROW(g.set(1, 1, 101), std::invalid_argument);
  EXPECT_THROW(g.set(1, 1, -128), std::invalid_argument);
  EXPECT_EQ(g.at(1, 1), kFree);  // unchanged by the refused writes
  for (const int v : {-1, 0, 50, 100}) {
    g.set(1, 1, static_cast<std::int8_t>(v));
    EXPECT_EQ(g.at(1, 1), v);
  }
}

TEST(OccupancyGrid, WorldCellTransformsRoundTripWithRotatedOrigin) {
  const OccupancyGrid g(10, 5, 0.2, Pose2(1.0, -2.0, 0.5));
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 10; ++x) {
      EXPECT_EQ(g.world_to_cell(g.cell_to_world(x, y)), (CellIndex{x, y}));
    }
  }
  const Eigen::Vector2d corner = g.grid_to_world({0.0, 0.0});
  EXPECT_NEAR(corner.x(), 1.0, 1e-12);
  EXPECT_NEAR(corner.y(), -2.0, 1e-12);
  const Eigen::Vector2d c10 = g.cell_to_world(1, 0);
  EXPECT_NEAR(c10.x(), 1.0 + 0.3 * std::cos(0.5) - 0.1 * std::sin(0.5), 1e-12);
  EXPECT_THROW(g.at(10, 0), std::out_of_range);
  EXPECT_THROW(g.at(0, -1), std::out_of_range);
  EXPECT_THROW(OccupancyGrid(0, 5, 0.1), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(5, 5, -0.1), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(5, 5, std::nan("")), std::invalid_argument);
  EXPECT_THROW(g.world_to_cell({std::nan(""), 0.0}), std::invalid_argument);
}

TEST(RayCasting, AgreesWithBruteForceSlabTests) {
  for (const Pose2 origin : {Pose2(0, 0, 0), Pose2(-1.3, 0.4, 0.3)}) {
    const OccupancyGrid g = random_grid(3, 0.05, origin);
    Random r(11);
    RayCastOptions o;
    o.max_range = 2.5;
    for (int i = 0; i < 300; ++i) {
      const Eigen::Vector2d s = g.grid_to_world({r.uniform(-5, 45), r.uniform(-5, 35)});
      const double heading = r.uniform(-kPi, kPi);
      const RayHit hit = cast_ray(g, s, heading, o);
      const double ref = brute_force_range(g, s, heading, o.max_range);
      ASSERT_NEAR(hit.range, ref, 1e-9) << "ray " << i;
      EXPECT_EQ(hit.hit, ref < o.max_range - 1e-4);
    }
  }
}

TEST(RayCasting, AxisAlignedRaysAndCells) {
  OccupancyGrid g(10, 10, 0.5, Pose2(), kFree);
  g.set(7, 2, kOccupied);
  RayCastOptions o;
  o.max_range = 20.0;
  const RayHit h = cast_ray(g, {0.25, 1.25}, 0.0, o);  // centre of cell (0, 2), heading +x
  EXPECT_TRUE(h.hit);
  EXPECT_NEAR(h.range, 3.5 - 0.25, 1e-12);
  EXPECT_EQ(h.cell, (CellIndex{7, 2}));
  const auto cells = cells_on_ray(g, {0.25, 1.25}, 0.0, o);
  ASSERT_EQ(cells.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(cells[i], (CellIndex{i, 2}));
  // Leaving the map without a hit returns max_range; starting in an obstacle returns 0.
  EXPECT_DOUBLE_EQ(cast_ray(g, {0.25, 1.25}, kPi, o).range, 20.0);
  EXPECT_DOUBLE_EQ(cast_ray(g, {3.6, 1.2}, 1.0, o).range, 0.0);
  // Unknown cells stop the ray only when asked to.
  g.set(3, 2, kUnknown);
  EXPECT_NEAR(cast_ray(g, {0.25, 1.25}, 0.0, o).range, 3.25, 1e-12);
  o.unknown_is_obstacle = true;
  EXPECT_NEAR(cast_ray(g, {0.25, 1.25}, 0.0, o).range, 1.25, 1e-12);
  o.max_range = -1.0;
  EXPECT_THROW(cast_ray(g, {0, 0}, 0.0, o), std::invalid_argument);
}

TEST(RayCasting, CellsOnRayAreFourConnected) {
  const OccupancyGrid g(50, 50, 0.1, Pose2(), kFree);
  Random r(5);
  RayCastOptions o;
  o.max_range = 10.0;
  for (int i = 0; i < 100; ++i) {
    const auto cells = cells_on_ray(g, {r.uniform(0, 5), r.uniform(0, 5)}, r.uniform(-kPi, kPi), o);
    for (std::size_t k = 1; k < cells.size(); ++k) {
      ASSERT_EQ(std::abs(cells[k].x - cells[k - 1].x) + std::abs(cells[k].y - cells[k - 1].y), 1);
    }
  }
}

TEST(DistanceField, MatchesBruteForceEuclideanDistance) {
  const OccupancyGrid g = random_grid(8, 0.02, Pose2());
  const cv::Mat d = distance_field(g);
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      double best = std::numeric_limits<double>::infinity();
      for (int v = 0; v < g.height(); ++v)
        for (int u = 0; u < g.width(); ++u)
          if (g.value(u, v) >= 65) best = std::min(best, std::hypot(u - x, v - y) * 0.1);
      ASSERT_NEAR(d.at<float>(y, x), best, 1e-4) << x << "," << y;
    }
  }
  const cv::Mat empty = distance_field(OccupancyGrid(4, 4, 0.1, Pose2(), kFree));
  EXPECT_TRUE(std::isinf(empty.at<float>(2, 2)));
}

TEST(LocalWindow, MatchesPointwiseLookupAndMarksOutsideUnknown) {
  const OccupancyGrid g = random_grid(4, 0.3, Pose2(0.5, -0.2, 0.2));
  const Pose2 pose(2.0, 1.0, 0.9);
  const OccupancyGrid w = extract_window(g, pose, 3.0, 2.0);
  ASSERT_EQ(w.width(), 30);
  ASSERT_EQ(w.height(), 20);
  int outside = 0;
  for (int y = 0; y < w.height(); ++y) {
    for (int x = 0; x < w.width(); ++x) {
      const Eigen::Vector2d p = pose.transform_point({(x + 0.5) * 0.1 - 1.5, (y + 0.5) * 0.1 - 1.0});
      const CellIndex c = g.world_to_cell(p);
      const std::int8_t expected = g.contains(c) ? g.value(c.x, c.y) : kUnknown;
      outside += !g.contains(c);
      ASSERT_EQ(w.value(x, y), expected);
    }
  }
  EXPECT_GT(outside, 0);  // the window sticks out of the map: the test covers both cases
  EXPECT_THROW(extract_window(g, pose, -1.0, 2.0), std::invalid_argument);
}

TEST(MapImage, Nav2LoadingRules) {
  cv::Mat img(1, 5, CV_8UC1);
  img.at<std::uint8_t>(0, 0) = 0;    // occ 1.0 -> occupied
  img.at<std::uint8_t>(0, 1) = 254;  // occ 0.004 -> free
  img.at<std::uint8_t>(0, 2) = 205;  // occ 0.196078 -> unknown with free_thresh 0.196
  img.at<std::uint8_t>(0, 3) = 128;  // occ 0.498 -> unknown (trinary) / 69 (scale)
  img.at<std::uint8_t>(0, 4) = 60;   // raw 60
  MapImageParams p;
  OccupancyGrid g = occupancy_from_image(img, 0.05, Pose2(), p);
  EXPECT_EQ(g.value(0, 0), 100);
  EXPECT_EQ(g.value(1, 0), 0);
  EXPECT_EQ(g.value(2, 0), -1);
  EXPECT_EQ(g.value(3, 0), -1);
  p.mode = MapMode::Scale;
  g = occupancy_from_image(img, 0.05, Pose2(), p);
  EXPECT_EQ(g.value(3, 0), static_cast<int>(std::rint((1 - 128 / 255.0 - 0.196) / (0.65 - 0.196) * 100)));
  p.mode = MapMode::Raw;
  g = occupancy_from_image(img, 0.05, Pose2(), p);
  EXPECT_EQ(g.value(0, 0), 0);
  EXPECT_EQ(g.value(1, 0), -1);
  EXPECT_EQ(g.value(4, 0), 60);
  p = MapImageParams();
  p.negate = true;
  g = occupancy_from_image(img, 0.05, Pose2(), p);
  EXPECT_EQ(g.value(0, 0), 0);
  EXPECT_EQ(g.value(1, 0), 100);
  p.free_thresh = 0.9;
  EXPECT_THROW(occupancy_from_image(img, 0.05, Pose2(), p), std::invalid_argument);
}

TEST(MapImage, RowsFlipAndTrinaryRoundTrip) {
  OccupancyGrid g(3, 2, 0.1, Pose2(), kFree);
  g.set(0, 0, kOccupied);  // bottom-left cell -> last image row
  g.set(2, 1, kUnknown);
  const cv::Mat img = image_from_occupancy(g, MapImageParams());
  EXPECT_EQ(img.at<std::uint8_t>(1, 0), 0);
  EXPECT_EQ(img.at<std::uint8_t>(0, 2), 205);
  EXPECT_EQ(img.at<std::uint8_t>(0, 0), 254);
  const OccupancyGrid back = occupancy_from_image(img, 0.1, Pose2(), MapImageParams());
  EXPECT_EQ(cv::countNonZero(back.cells() != g.cells()), 0);
}

TEST(MapImage, ScaleModeUsesAlphaForUnknown) {
  OccupancyGrid g(2, 1, 0.1, Pose2(), kUnknown);
  g.set(1, 0, 40);
  MapImageParams p;
  p.mode = MapMode::Scale;
  const cv::Mat img = image_from_occupancy(g, p);
  ASSERT_EQ(img.type(), CV_8UC4);
  EXPECT_EQ(img.at<cv::Vec4b>(0, 0)[3], 0);
  EXPECT_EQ(img.at<cv::Vec4b>(0, 1)[3], 255);
  const OccupancyGrid back = occupancy_from_image(img, 0.1, Pose2(), p);
  EXPECT_EQ(back.value(0, 0), -1);
  EXPECT_NEAR(back.value(1, 0), std::rint((0.4 - 0.196) / (0.65 - 0.196) * 100), 1);
}

TEST(MapImage, ReadErrorsNameTheFile) {
  EXPECT_THROW(read_image("/nonexistent/kiseki_map.pgm"), std::runtime_error);
  const std::string bad = testing::TempDir() + "kiseki_corrupt.pgm";
  FILE* f = std::fopen(bad.c_str(), "wb");
  std::fputs("P5\n10 10\n255\nabc", f);  // header promises 100 bytes, 3 follow
  std::fclose(f);
  try {
    read_image(bad);
    FAIL() << "a truncated PGM must not decode";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("kiseki_corrupt.pgm"), std::string::npos);
  }
}
