// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The swept-sector caster against the exact cell walk (cast_ray) and the distance-field caster
// (RangeCaster): equal to rounding on random rays in a synthetic room and in a real map, with
// nav2's stopping rule at its edge cases.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "filter_scenes.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/grid/map_image.hpp"
#include "kiseki/grid/range_caster.hpp"
#include "kiseki/grid/sector_caster.hpp"
#include "kiseki/io/image_file.hpp"

using namespace kiseki;
using kiseki::test::room;

namespace {

constexpr double kRounding = 1e-9;  // m: "equal to rounding"

// The Intel Research Lab map (the CARMEN log's map image) at 0.05 m, read where the recorded
// datasets live beside the repository.
OccupancyGrid intel_map() {
  const cv::Mat image = read_image(std::string(KISEKI_SHARED_DATA) + "/carmen/intel-corrected.png");
  return occupancy_from_image(image, 0.05, Pose2(-5.0, -5.0, 0.0), MapImageParams{});
}

// Rays from uniform points of a box around the map (inside it, in walls, in unknown space and
// outside it) compared with cast_ray and RangeCaster.
void expect_exact(const OccupancyGrid& g, bool unknown, int per_octant, int rays, std::uint64_t seed) {
  const SectorCaster sector(g, unknown, 65, per_octant);
  const RangeCaster field(g, unknown);
  RayCastOptions o;
  o.unknown_is_obstacle = unknown;
  const double w = g.width() * g.resolution(), h = g.height() * g.resolution();
  const Eigen::Vector2d lo = g.grid_to_world({0.0, 0.0}) - Eigen::Vector2d(1.0, 1.0);
  Random rng(seed);
  int hits = 0;
  for (int k = 0; k < rays; ++k) {
    const double x = lo.x() + rng.uniform(0.0, w + 2.0), y = lo.y() + rng.uniform(0.0, h + 2.0);
    const double heading = rng.uniform(-kPi, kPi), reach = rng.uniform(0.0, 12.0);
    o.max_range = reach;
    const RayHit want = cast_ray(g, {x, y}, heading, o);
    hits += want.hit;
    ASSERT_NEAR(sector.range(x, y, heading, reach), want.range, kRounding)
        << "unknown_stops " << unknown << " sectors " << per_octant << " at " << x << " " << y
        << " heading " << heading << " reach " << reach;
    ASSERT_NEAR(sector.range_along(x, y, std::cos(heading), std::sin(heading), reach),
                field.range(x, y, heading, reach), kRounding);
  }
  EXPECT_GT(hits, rays / 4);  // the rays do meet walls, not only the reach
}

}  // namespace

TEST(SectorCaster, EqualsCastRayInARoom) {
  for (bool unknown : {false, true}) {
    for (int per_octant : {1, 3, 8}) expect_exact(room(), unknown, per_octant, 20000, 3);
  }
}

TEST(SectorCaster, EqualsCastRayInARotatedRoom) {
  OccupancyGrid g = room();
  g.set_origin(Pose2(2.0, -1.0, 0.7));
  expect_exact(g, true, 8, 20000, 5);
}

TEST(SectorCaster, EqualsCastRayInTheIntelMap) {
  const OccupancyGrid g = intel_map();
  for (bool unknown : {false, true}) expect_exact(g, unknown, 8, 50000, 7);
}

TEST(SectorCaster, ScansFromFreeCellsOfTheIntelMapEqualRangeCaster) {
  // What the beam model asks: 360 beams from poses on free cells, up to the laser's reach
  // (the Intel log's 81.83 m) or short of it, cast scan by scan.
  const OccupancyGrid g = intel_map();
  const SectorCaster sector(g);
  const RangeCaster field(g);
  std::vector<double> cos_b(360), sin_b(360), reach(360), got(360);
  for (int b = 0; b < 360; ++b) {
    cos_b[b] = std::cos(kPi * b / 180.0), sin_b[b] = std::sin(kPi * b / 180.0);
    reach[b] = b % 3 == 0 ? 81.83 : 0.5 + 0.02 * b;
  }
  Random rng(9);
  int poses = 0;
  while (poses < 300) {
    const int cx = static_cast<int>(rng.uniform(0, g.width())), cy = static_cast<int>(rng.uniform(0, g.height()));
    if (!is_free(g.value(cx, cy))) continue;
    ++poses;
    const Eigen::Vector2d p = g.grid_to_world({cx + rng.uniform(0, 1), cy + rng.uniform(0, 1)});
    const Pose2 sensor(p.x(), p.y(), rng.uniform(-kPi, kPi));
    sector.scan(sensor, cos_b.data(), sin_b.data(), reach.data(), 360, got.data());
    for (int b = 0; b < 360; ++b) {
      const double heading = sensor.theta + kPi * b / 180.0;
      ASSERT_NEAR(got[b], field.range(p.x(), p.y(), heading, reach[b]), kRounding) << poses << " " << b;
      ASSERT_NEAR(sector.range(p.x(), p.y(), heading, reach[b]), got[b], kRounding);
    }
  }
}

TEST(SectorCaster, StopsWhereNav2Stops) {
  // 2 m x 1 m of free cells with one occupied and one unknown cell on the row of y = 0.5.
  OccupancyGrid g(40, 20, 0.05, Pose2(), kFree);
  g.set(30, 10, kOccupied);
  g.set(20, 10, kUnknown);
  g.set(5, 10, 64);  // below the threshold: free
  const SectorCaster stops(g, true), passes(g, false);
  EXPECT_NEAR(stops.range(0.12, 0.52, 0.0, 10.0), 1.0 - 0.12, kRounding);  // the unknown cell
  EXPECT_NEAR(passes.range(0.12, 0.52, 0.0, 10.0), 1.5 - 0.12, kRounding);  // the occupied one
  EXPECT_DOUBLE_EQ(stops.range(1.52, 0.52, 0.0, 10.0), 0.0);                // starts in it
  EXPECT_DOUBLE_EQ(stops.range(1.02, 0.52, 0.0, 10.0), 0.0);                // starts in unknown
  EXPECT_NEAR(passes.range(1.02, 0.52, 0.0, 10.0), 0.5 - 0.02, kRounding);
  // The edge of the map ends a ray: no wall there, so the reach.
  EXPECT_DOUBLE_EQ(stops.range(0.12, 0.52, kPi / 2, 10.0), 10.0);
  EXPECT_DOUBLE_EQ(stops.range(0.12, 0.52, kPi, 7.5), 7.5);
  // The reach ends a ray before the wall; 0 reach is 0.
  EXPECT_DOUBLE_EQ(passes.range(0.12, 0.52, 0.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(passes.range(0.12, 0.52, 0.0, 0.0), 0.0);
  // From outside the map: the wall is met where the ray meets it, or the ray misses the map.
  EXPECT_NEAR(passes.range(-1.0, 0.52, 0.0, 10.0), 2.5, kRounding);
  EXPECT_DOUBLE_EQ(passes.range(-1.0, 0.52, kPi, 10.0), 10.0);
  EXPECT_DOUBLE_EQ(passes.range(-1.0, 0.52, 0.0, 2.0), 2.0);
}

TEST(SectorCaster, StartsFarOutsideTheMap) {
  // 1 km away the walk starts where the ray enters the map, as cast_ray's; from 1e200 m the
  // numbers lose every digit of the map, and the range is still one in [0, reach].
  const OccupancyGrid g = room();
  const SectorCaster c(g);
  RayCastOptions o;
  o.unknown_is_obstacle = true;
  o.max_range = 2000.0;
  Random rng(12);
  for (int k = 0; k < 200; ++k) {
    const double y = rng.uniform(-0.4, 5.4), heading = rng.uniform(-0.001, 0.001);
    EXPECT_NEAR(c.range(-1000.0, y, heading, 2000.0), cast_ray(g, {-1000.0, y}, heading, o).range, 1e-6);
  }
  const double far = c.range(1e200, 1e200, -2.3, 1e201);
  EXPECT_TRUE(far >= 0.0 && far <= 1e201);
}

TEST(SectorCaster, RefusesBadInput) {
  const OccupancyGrid g = room();
  EXPECT_THROW(SectorCaster(g, true, 65, 0), std::invalid_argument);
  EXPECT_THROW(SectorCaster(g, true, 65, 65), std::invalid_argument);
  const SectorCaster c(g);
  EXPECT_THROW(c.range(NAN, 0.0, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(c.range(0.0, 0.0, INFINITY, 1.0), std::invalid_argument);
  EXPECT_THROW(c.range(0.0, 0.0, 0.0, -1.0), std::invalid_argument);
  EXPECT_THROW(c.range_along(0.0, 0.0, NAN, 0.0, 1.0), std::invalid_argument);
  const double one = 1.0, zero = 0.0, bad_reach = -1.0;
  double out = 0.0;
  EXPECT_THROW(c.scan(Pose2(NAN, 0, 0), &one, &zero, &one, 1, &out), std::invalid_argument);
  EXPECT_THROW(c.scan(Pose2(), &one, &zero, &bad_reach, 1, &out), std::invalid_argument);
}

TEST(SectorCaster, TableIsOneBytePerCellAndSector) {
  const OccupancyGrid g = room();
  const SectorCaster c(g, true, 65, 4);
  EXPECT_EQ(c.sectors(), 32);
  EXPECT_EQ(c.memory_bytes(), static_cast<std::size_t>(200 * 120) * 32);
}
