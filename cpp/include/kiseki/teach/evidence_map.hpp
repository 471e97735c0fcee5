// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// An evidence-counting variant of the thesis' environment-map merge (sec. 3.4), beyond the
/// thesis. The thesis' rule (L free over M occupied -> free, forever) lets one stray beam erase
/// a wall that a hundred others ended on. Here every M cell counts the local maps that saw it
/// free (a beam passed) and those whose beam ended in it (a hit); it turns free only when its
/// free observations outweigh its hits. The space behind obstacles (occupied in L but no hit)
/// is no evidence of an obstacle: it makes a cell occupied only while nothing else is known of
/// it, as the thesis' "unknown -> L's value" does, so a room first seen from behind its wall
/// becomes free as soon as the robot looks into it. The output has the thesis' three states:
///   unknown   never in view;
///   free      free count > hit count;
///   occupied  hit count >= free count > 0, or hit count > 0, or only ever hidden.
class EvidenceMap {
 public:
  /// `frame` gives the geometry (size, resolution, origin); its cells are not used.
  explicit EvidenceMap(const OccupancyGrid& frame);

  /// Places a local map L at `pose` (each L cell updates the M cell under its centre, as
  /// merge_local_map does). `hits` is L's CV_8U mask of beam-end cells (nonzero = a beam ended
  /// there), of L's size. Returns the number of M cells whose state changed.
  int merge(const OccupancyGrid& local, const cv::Mat& hits, const Pose2& pose);

  /// The map in the thesis' three states.
  OccupancyGrid map() const;

  const cv::Mat& free_counts() const { return free_; }  ///< CV_32S, per M cell
  const cv::Mat& hit_counts() const { return hits_; }   ///< CV_32S, per M cell

 private:
  std::int8_t state(int x, int y) const;
  OccupancyGrid frame_;
  cv::Mat free_, hits_;  // CV_32S counts
  cv::Mat hidden_;       // CV_8U: seen only as the space behind an obstacle
};

}  // namespace kiseki
