// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// libFuzzer target: the OctoMap binary tree (.bt) reader kiseki::OctreeWorld::read_binary
// (kiseki.sim.scene's `octomap:` worlds), then what a scene does with the tree: its bounds,
// ray casts and a rasterised height band. std::runtime_error is the documented refusal;
// anything else, a sanitizer report, a hang (-timeout) or a cast outside [0, max_range] is a
// finding.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "kiseki/sim/octree_world.hpp"
#include "temp_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const kiseki::OctreeWorld world = [&] {
      const kiseki_fuzz::TempInput input(data, size);  // removed after the read
      return kiseki::OctreeWorld::read_binary(input.path());
    }();
    (void)world.bounds();
    (void)world.occupied_leaves();
    const Eigen::Vector3d origin(0.1, 0.2, 0.5);
    for (const Eigen::Vector3d direction :
         {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0.6, 0.8, 0)}) {
      const double d = world.cast(origin, direction, 10.0);
      if (!(d >= 0.0 && d <= 10.0)) std::abort();
    }
    kiseki::OccupancyGrid grid(40, 40, 0.25, kiseki::Pose2{-5.0, -5.0, 0.0});
    world.rasterize_band(0.0, 2.0, grid);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
