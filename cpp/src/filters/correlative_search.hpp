// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The branch-and-bound search of CorrelativeScanMatcher::match (Hess et al. 2016, Algorithm 3):
// private to the matcher's sources.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <vector>

#include "kiseki/filters/correlative_scan_matcher.hpp"

namespace kiseki {

/// One search: the rotated scans' cell offsets, the shared threshold and its witnesses (a set of
/// pairwise far poses found), and per worker the leaves it found.
struct CorrelativeScanMatcher::Search {
  /// A lattice pose found by the search.
  struct Leaf {
    double score;
    std::int64_t index;  // (heading * height + y) * width + x
    int x, y, k;
    Pose2 pose;
  };
  /// The selection's order: best score first, equal scores in lattice order.
  static bool before(const Leaf& a, const Leaf& b) {
    return a.score > b.score || (a.score == b.score && a.index < b.index);
  }

  explicit Search(const CorrelativeScanMatcher& matcher) : m(matcher) {}
  const CorrelativeScanMatcher& m;
  int headings = 0, beams = 0;
  std::vector<int> dx, dy;  // [heading * beams + b]: a beam end's cell offset from the laser's cell
  std::vector<std::ptrdiff_t> off;  // the same as an offset on the padded layout: dy * pitch + dx
  double margin = 0.0;
  // A disc restriction: per heading, its centre as the laser's cell coordinates (cell i's centre
  // at i; the robot's position is the laser's shifted by the heading's rotated sensor offset),
  // and its radius in cells.
  const SearchDisc* disc = nullptr;
  std::vector<double> disc_x, disc_y;
  double disc_radius = 0.0;
  std::atomic<double> threshold{-std::numeric_limits<double>::infinity()};

  struct Worker {
    std::vector<Leaf> leaves;
    std::size_t compacted = 0;
  };
  std::mutex far_mutex;
  std::vector<Leaf> far;  // shared by the workers, so the threshold rises as fast as on one

  /// Beam b's score term at a node: P_level at its end, outside_ off the stored layout. One
  /// unsigned comparison per axis finds the ends off it; the read is of cell 0 then, not used.
  struct Terms {
    const float* grid;
    const int *ox, *oy;
    const std::ptrdiff_t* lin;
    unsigned pitch, rows;
    int gx, gy;
    std::ptrdiff_t base;
    float outside;
    float operator()(int b) const {
      const bool in = static_cast<unsigned>(gx + ox[b]) < pitch && static_cast<unsigned>(gy + oy[b]) < rows;
      const float v = grid[in ? base + lin[b] : 0];
      return in ? v : outside;
    }
  };

  Terms terms(int level, int x, int y, int k) const {
    const int pad = m.pitch_ - m.frame_.width();
    const std::size_t at = static_cast<std::size_t>(k) * beams;
    Terms t{m.pooled_[static_cast<std::size_t>(level)].data(), dx.data() + at, dy.data() + at, off.data() + at,
            static_cast<unsigned>(m.pitch_), static_cast<unsigned>(m.rows_), x + pad, y + pad, 0, m.outside_};
    t.base = static_cast<std::ptrdiff_t>(t.gy) * m.pitch_ + t.gx;
    return t;
  }

  /// A lattice pose's score: the terms summed in beam order, as the likelihood field's
  /// log_likelihoods sums them, so a hypothesis' score is the model's own.
  double score(int x, int y, int k) const {
    const Terms t = terms(0, x, y, k);
    double sum = 0.0;
    for (int b = 0; b < beams; ++b) sum += t(b);
    return sum;
  }

  /// An upper bound of the scores of the lattice poses under a node (eqs. (13)-(15)); at level 0
  /// the pose's score. Above it, the P_level terms in four running sums, whose rounding differs
  /// from score()'s beam order; `margin` exceeds both sums' rounding errors together (n^2 u
  /// max|term| each, u = 2^-53), so a pose whose score equals the threshold is never pruned and
  /// the result stays the exhaustive search's.
  double bound(int level, int x, int y, int k) const {
    if (level == 0) return score(x, y, k);
    const Terms t = terms(level, x, y, k);
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    int b = 0;
    for (; b + 4 <= beams; b += 4) s0 += t(b), s1 += t(b + 1), s2 += t(b + 2), s3 += t(b + 3);
    for (; b < beams; ++b) s0 += t(b);
    return (s0 + s1) + (s2 + s3) + margin;
  }

  /// Can a cell of the side x side block at (x, y) hold a pose on the disc's side? (Exact up to a
  /// margin of 1e-6 cell that keeps a node; the leaves are tested exactly.)
  bool on_side(int level, int x, int y, int k) const;
  /// Is a pose on the disc's side (every pose without a disc)?
  bool kept(const Pose2& p) const;
  /// Are two poses within scale * (min_distance, min_angle) of each other?
  bool close(const Pose2& a, const Pose2& b, double scale) const;
  /// Raises the shared threshold to t, never lowers it.
  void raise(double t);
  /// Keeps a lattice pose scoring at least the threshold, and updates the far set.
  void leaf(Worker& w, double score, int x, int y, int k);
  /// Hess et al. Algorithm 3: depth first, children in order of their bounds.
  void descend(Worker& w, int level, int x, int y, int k, double b);
};

}  // namespace kiseki
