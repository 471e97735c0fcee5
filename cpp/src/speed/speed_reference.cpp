// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/speed/speed_reference.hpp"

#include <cmath>
#include <stdexcept>

#include "kiseki/core/angle.hpp"

namespace kiseki {

void check_params(const SpeedReferenceParams& p) {
  if (!(std::isfinite(p.v_max) && p.v_max > 0)) throw std::invalid_argument("v_max must be positive");
  if (!(p.occlusion.half_angle > 0 && p.occlusion.half_angle <= kPi)) {
    throw std::invalid_argument("half_angle must be in (0, pi] rad");
  }
  if (p.occlusion.free_threshold < 0) throw std::invalid_argument("free_threshold must be in 0..100");
  width_factor(p.w2, p.w1, p.w2, p.a);  // checks w1, w2 and a
  if (!(std::isfinite(p.half_band) && p.half_band > 0)) {
    throw std::invalid_argument("half_band must be positive");
  }
}

SpeedReference speed_reference(const OccupancyGrid& map, const Pose2& sensor_pose, const PlanarScan& scan,
                               double heading, const SpeedReferenceParams& params) {
  check_params(params);
  check_scan(scan);
  SpeedReference out;
  double factor = 1.0;
  if (params.use_occlusion) {
    out.occlusion = occlusion_ratio(map, sensor_pose, scan, heading, params.occlusion);
    factor *= out.occlusion.ratio;  // eq. 1
  }
  if (params.use_width) {
    out.passage = passage_width(scan, normalize_angle(heading - sensor_pose.theta), params.half_band);
    out.width_factor = width_factor(out.passage.width, params.w1, params.w2, params.a);
    factor *= out.width_factor;  // eq. 2
  }
  out.v_ref = params.v_max * factor;  // eq. 4
  return out;
}

}  // namespace kiseki
