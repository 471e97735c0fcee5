// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include "kiseki/speed/occlusion_ratio.hpp"
#include "kiseki/speed/passage_width.hpp"

namespace kiseki {

/// The parameters of the combined speed reference (the paper's sec. 4 values as defaults).
struct SpeedReferenceParams {
  double v_max = 0.5;                      ///< m/s
  OcclusionRatioOptions occlusion;         ///< theta = 90 deg
  double w1 = 0.70;                        ///< m, the robot's width
  double w2 = 2.0;                         ///< m, a passage that needs no slowing down
  double a = 4.9;                          ///< 1/m, the sigmoid's slope
  double half_band = 0.05;                 ///< m, the strip across the heading where w is measured
  bool use_occlusion = true;               ///< method 1 (eq. 1)
  bool use_width = true;                   ///< method 2 (eq. 2)
};

struct SpeedReference {
  double v_ref = 0.0;          ///< m/s, eq. 4 (or 1, or 2)
  OcclusionRatio occlusion;    ///< eq. 1's ratio (1 when not used)
  PassageWidth passage;        ///< w (zero when not used)
  double width_factor = 1.0;   ///< f(w) (1 when not used)
};

/// Eq. 4: v_max^ref = v_max * R_recognize / (R_map_free intersect R_sensor) * f(w), with either
/// factor left out when its method is off. heading: the direction of motion in the map frame.
SpeedReference speed_reference(const OccupancyGrid& map, const Pose2& sensor_pose, const PlanarScan& scan,
                               double heading, const SpeedReferenceParams& params);

/// Throws std::invalid_argument naming the first bad parameter.
void check_params(const SpeedReferenceParams& params);

}  // namespace kiseki
