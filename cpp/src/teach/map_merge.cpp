// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/teach/map_merge.hpp"

#include <cmath>
#include <stdexcept>

namespace kiseki {

int merge_local_map(OccupancyGrid& environment, const OccupancyGrid& local, const Pose2& pose) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    throw std::invalid_argument("merge_local_map: pose must be finite");
  }
  int changed = 0;
  for (int j = 0; j < local.height(); ++j) {
    for (int i = 0; i < local.width(); ++i) {
      const std::int8_t l = local.value(i, j);
      if (l < 0) continue;  // outside the field of view
      const Eigen::Vector2d world = pose.transform_point(local.cell_to_world(i, j));
      const CellIndex c = environment.world_to_cell(world);
      if (!environment.contains(c)) continue;
      std::int8_t& m = environment.cells().ptr<std::int8_t>(c.y)[c.x];
      std::int8_t next = m;
      if (m < 0) next = l;                              // unknown -> the local value
      else if (l == kFree && m == kOccupied) next = kFree;  // observed free wins
      changed += next != m;
      m = next;
    }
  }
  return changed;
}

}  // namespace kiseki
