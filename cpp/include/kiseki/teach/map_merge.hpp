// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// Places a local map L (robot frame, cells 0 free / 100 occupied / -1 outside the view) at a
/// pose in the environment map M with the teaching-and-playback thesis' rules (sec. 3.4): M
/// unknown -> L's value; L free over M occupied -> free (whatever may move away is free);
/// L occupied over M free -> stays free; equal -> unchanged. Each L cell updates the M cell
/// under its centre. Returns the number of M cells changed.
int merge_local_map(OccupancyGrid& environment, const OccupancyGrid& local, const Pose2& pose);

}  // namespace kiseki
