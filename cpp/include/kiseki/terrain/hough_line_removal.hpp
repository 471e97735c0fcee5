// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/terrain/sphere_elevation_map.hpp"

namespace kiseki {

/// The paper's plane removal (paper 003 sec. 5.1): in one tilt scan (a row of the S-DEM, fixed
/// theta) a plane is a straight line; lines are found by a Hough transform and their points
/// removed, so that walls and ceilings (no features, much data) do not dominate the match.
///
/// The transform votes with the scan's own points (u, v) = (r cos phi, r sin phi) in the scan's
/// plane, not with a rasterised image: a 1 deg scan holds at most a few hundred points, and
/// voting with them keeps their positions exact where an image would round them to pixels.
/// The strongest line (votes in the (alpha, rho) bin) is refitted by total least squares to the
/// points of its bin, its points within `inlier_distance` are removed, and the next line is
/// searched, until the strongest has fewer than `min_votes` points or `max_lines` were taken.
struct HoughLineParams {
  double angle_step_deg = 1.0;    ///< alpha's bin
  double rho_step = 0.03;         ///< rho's bin (m)
  double inlier_distance = 0.03;  ///< a point this close to the fitted line is on it (m)
  std::size_t min_votes = 30;     ///< fewer points on the strongest line: stop
  int max_lines = 8;              ///< per scan
  void validate() const;
};

struct HoughRemovalResult {
  SphereElevationMap kept;       ///< the map without the removed cells (NaN there)
  std::vector<std::uint8_t> removed;  ///< per cell: 1 when removed
  std::size_t lines = 0;  ///< lines found, summed over the scans
};

/// Hough line removal on every tilt scan of `map`.
HoughRemovalResult remove_lines_hough(const SphereElevationMap& map, const HoughLineParams& params = {});

}  // namespace kiseki
