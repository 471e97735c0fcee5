// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// libFuzzer target: the OctoMap binary tree (.bt) reader kiseki::OctreeWorld::read_binary
// (kiseki.sim.scene's `octomap:` worlds), then what a scene does with the tree: its bounds,
// ray casts and a rasterised height band. std::runtime_error is the documented refusal;
// anything else, a sanitizer report, a hang (-timeout) or a cast outside [0, max_range] is a
// finding.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "kiseki/sim/octree_world.hpp"

namespace {

const std::string& input_path() {
  static const std::string path = [] {
    char name[] = "/tmp/kiseki-fuzz-octree-XXXXXX";
    const int fd = mkstemp(name);
    if (fd < 0) std::abort();
    close(fd);
    return std::string(name);
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(input_path(), std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const kiseki::OctreeWorld world = kiseki::OctreeWorld::read_binary(input_path());
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
