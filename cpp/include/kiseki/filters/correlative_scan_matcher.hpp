// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/core/pose.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/models/likelihood_field.hpp"

namespace kiseki {

/// Settings of the global correlative scan matcher.
struct CorrelativeMatcherParams {
  /// The per-cell score: the likelihood field's tabulated log pz (product combination; its
  /// max_beams is the beam subsampling rule, nav2's: every step-th beam from the first).
  LikelihoodFieldParams likelihood;
  /// Levels of the multi-resolution search above the finest lattice: a node at depth h covers
  /// 2^h x 2^h cells (Hess et al. 2016, sec. V.C, the "branch-and-bound depth"); capped at the
  /// first level whose node covers the whole map (deeper ones find the same poses).
  int depth = 7;
  /// rad between headings; 0 = Hess et al. 2016 eq. (7): acos(1 - r^2 / (2 d_max^2)), r the
  /// map resolution and d_max the longest range used, rounded so that the headings divide 2 pi.
  double angular_step = 0.0;
  int hypotheses = 5;            ///< k: how many distinct poses to return
  double min_distance = 0.5;     ///< m: two poses closer than this and
  double min_angle = 0.5;        ///< rad: nearer in heading than this are one hypothesis
  /// The laser only on known free cells (is_free: 0..19), as MCL's uniform poses: nodes whose
  /// cells hold none are not searched.
  bool free_only = true;
  int threads = 0;               ///< 0 = every hardware thread; the result is the same for any
  void validate() const;
};

/// One pose hypothesis: the robot pose in the map frame, its score (the sum over the used beams
/// of the likelihood field's log pz at their ends) and its place on the search lattice.
struct PoseHypothesis {
  Pose2 pose;
  double score = 0.0;
  int cell_x = 0, cell_y = 0, heading = 0;
};

/// A disc that restricts a search: with `inside`, only lattice poses whose robot position is at
/// most `radius` m from (x, y) (map frame) are scored; without, only those more than `radius`
/// m from it. The best pose of each side of a disc is exact, as the unrestricted search is.
struct SearchDisc {
  double x = 0.0, y = 0.0;
  double radius = 0.0;
  bool inside = true;
};

/// Global relocalization from one scan by branch-and-bound correlative scan matching over the
/// whole map (Olson, "Real-time correlative scan matching", ICRA 2009, sec. III-IV: the
/// multi-resolution search whose coarse cells hold the maximum of the fine ones; Hess, Kohler,
/// Rapp, Andor, "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016, sec. V: Algorithm 3).
///
/// The lattice: the laser at every (free_only: known free) cell centre of the map and at
/// headings k * angular_step in the map's grid frame. The score of a lattice pose is the likelihood field's log-likelihood
/// of the subsampled scan there (LikelihoodFieldModel::log_likelihoods gives the same value).
/// Precomputed grids P_h hold, per cell, the maximum score term over the 2^h x 2^h cells
/// starting there (sec. V.C), so the sum of P_h over a node's beam ends bounds the score of
/// every lattice pose below it (eq. (13)-(15)). Each heading is one rotated scan whose beam ends
/// are rounded to cell offsets once; a node is then a translation of them by whole cells.
///
/// Search: depth first, the child with the best bound first, a node pruned when its bound is
/// below the threshold. The result is the greedy selection over all lattice poses sorted by
/// score (ties by lattice index): the best, then the best not within min_distance and
/// min_angle of one taken, up to k. The threshold is the lowest score of k found poses that are
/// pairwise at least 2 min_distance or 2 min_angle apart: each taken pose is near at most one of
/// them, so the k-th taken score is never below it, and no pose the selection would take is
/// pruned. Threads share that threshold; the result does not depend on their number.
class CorrelativeScanMatcher {
 public:
  /// Builds the score table and the max-pooled grids for scans of this max range.
  CorrelativeScanMatcher(const OccupancyGrid& map, double max_range,
                         const CorrelativeMatcherParams& params = {});
  /// The k best distinct hypotheses for one scan (angles in rad, ranges in m, in the laser
  /// frame), best first. Empty when no beam returned, or when `disc` leaves no pose. With a
  /// disc, the selection runs over the poses on its side only (a node none of whose cells can
  /// hold such a pose is pruned).
  std::vector<PoseHypothesis> match(const double* angles, const float* ranges, std::size_t n,
                                    const SearchDisc* disc = nullptr) const;
  /// The robot pose of a lattice point: the laser at the cell's centre, heading
  /// heading * 2 pi / headings in the grid frame.
  Pose2 lattice_pose(int cell_x, int cell_y, int heading, int headings) const;
  /// Headings on the lattice for a scan: 2 pi / angular_step, or eq. (7) for the longest used
  /// range, rounded up. 0 when no beam returned.
  int headings(const double* angles, const float* ranges, std::size_t n) const;
  const CorrelativeMatcherParams& params() const { return params_; }
  double max_range() const { return max_range_; }
  double resolution() const { return frame_.resolution(); }
  /// Cells the laser is placed at (free_only: the known free cells; else every cell): the
  /// lattice holds this many poses per heading.
  std::size_t lattice_cells() const;

 private:
  struct Search;
  std::size_t index(int x, int y) const;  // (x, y) of the map's cells on the padded layout
  float value(int level, int x, int y) const;
  bool has_free(int level, int x, int y) const;
  CorrelativeMatcherParams params_;
  double max_range_;
  OccupancyGrid frame_;
  // Every level on one layout: pitch_ x rows_ cells from x = y = -(2^depth - 1).
  int pitch_ = 0, rows_ = 0;
  std::vector<std::vector<float>> pooled_;  // P_h
  std::vector<std::vector<std::uint8_t>> free_;  // per level: a free cell in the block
  float outside_ = 0.0f;
  double magnitude_ = 0.0;  // the largest |score term|: the bounds' rounding margin
};

}  // namespace kiseki
