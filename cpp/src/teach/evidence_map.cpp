// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/teach/evidence_map.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace kiseki {

EvidenceMap::EvidenceMap(const OccupancyGrid& frame)
    : frame_(frame.clone()),
      free_(frame.height(), frame.width(), CV_32SC1, cv::Scalar(0)),
      hits_(frame.height(), frame.width(), CV_32SC1, cv::Scalar(0)),
      hidden_(frame.height(), frame.width(), CV_8UC1, cv::Scalar(0)) {}

std::int8_t EvidenceMap::state(int x, int y) const {
  const int f = free_.at<std::int32_t>(y, x), h = hits_.at<std::int32_t>(y, x);
  if (f > h) return kFree;
  if (h > 0 || hidden_.at<std::uint8_t>(y, x)) return kOccupied;
  return kUnknown;
}

int EvidenceMap::merge(const OccupancyGrid& local, const cv::Mat& hits, const Pose2& pose) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    throw std::invalid_argument("EvidenceMap.merge: pose must be finite");
  }
  if (hits.type() != CV_8UC1 || hits.rows != local.height() || hits.cols != local.width()) {
    throw std::invalid_argument("EvidenceMap.merge: hits must be a uint8 mask of the local map's size");
  }
  int changed = 0;
  for (int j = 0; j < local.height(); ++j) {
    for (int i = 0; i < local.width(); ++i) {
      const std::int8_t l = local.value(i, j);
      if (l < 0) continue;  // outside the field of view
      const CellIndex c = frame_.world_to_cell(pose.transform_point(local.cell_to_world(i, j)));
      if (!frame_.contains(c)) continue;
      const std::int8_t before = state(c.x, c.y);
      if (l == kFree) {
        auto& n = free_.at<std::int32_t>(c.y, c.x);
        if (n < std::numeric_limits<std::int32_t>::max()) ++n;
      } else if (hits.at<std::uint8_t>(j, i)) {
        auto& n = hits_.at<std::int32_t>(c.y, c.x);
        if (n < std::numeric_limits<std::int32_t>::max()) ++n;
      } else {
        hidden_.at<std::uint8_t>(c.y, c.x) = 1;
      }
      changed += state(c.x, c.y) != before;
    }
  }
  return changed;
}

OccupancyGrid EvidenceMap::map() const {
  OccupancyGrid out = frame_.clone();
  for (int y = 0; y < out.height(); ++y) {
    auto* row = out.cells().ptr<std::int8_t>(y);
    for (int x = 0; x < out.width(); ++x) row[x] = state(x, y);
  }
  return out;
}

}  // namespace kiseki
