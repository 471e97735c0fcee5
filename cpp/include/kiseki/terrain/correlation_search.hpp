// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/terrain/sphere_elevation_map.hpp"

namespace kiseki {

/// The candidate translations of the correlation search (paper 003 sec. 6): a box in the
/// previous sensor frame, both ends included. The paper's: x 0..70 cm, y -50..50 cm,
/// z -30..30 cm, 2 cm steps: 36 x 51 x 31 = 56,916 candidates.
struct TranslationGrid {
  double x_min = 0.0, x_max = 0.70;
  double y_min = -0.50, y_max = 0.50;
  double z_min = -0.30, z_max = 0.30;
  double step = 0.02;
  /// Throws std::invalid_argument naming the field: non-finite values, step <= 0 (a grid of
  /// zero steps), an inverted range, more than 10^8 candidates.
  void validate() const;
  int nx() const;
  int ny() const;
  int nz() const;
  std::size_t size() const { return static_cast<std::size_t>(nx()) * ny() * nz(); }
  /// Candidate k, x slowest and z fastest.
  Eigen::Vector3d at(std::size_t k) const;
};

/// Eq. 4 as printed sums over the cells where both maps have data, so a candidate that
/// overlaps less costs less; `mean` divides by the sum of the weights (our default, see
/// CorrelationOptions).
enum class CorrelationCost { sum, mean };

struct CorrelationOptions {
  CorrelationCost cost = CorrelationCost::mean;
  /// Candidates whose virtual map shares fewer cells with the current one are not scored
  /// (their cost is +inf): a match on a handful of cells means nothing.
  std::size_t min_overlap = 50;
  int threads = 0;  ///< 0: every hardware thread
  void validate() const;
};

struct CorrelationResult {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double cost = 0.0;
  std::size_t overlap = 0;   ///< cells shared at the best candidate
  std::size_t index = 0;     ///< the best candidate in the grid's order
  std::size_t evaluated = 0; ///< candidates scored
  /// Exhaustive search only: every candidate's cost (x slowest), for plotting the surface.
  std::vector<double> costs;
};

/// The correlation search of paper 003 (eq. 4): the previous local map's points, seen from a
/// candidate centre (x_v, y_v, z_v), make a virtual S-DEM r_v (eq. 3, the nearest point per
/// cell); its cost against the current S-DEM r_cur is
///     d = sum over cells with data in both of (r_v - r_cur)^2 cos(phi),
/// minimised over the candidates. The attitude change between the two sweeps comes from the
/// gyro and is not searched: `rotation` turns the current sensor frame into the previous one
/// (R_prev^T R_cur), so a previous point p is q = R^T (p - t) in the current frame.
///
/// The angles of eq. 3 use a polynomial arctangent in float arithmetic (error below 2e-7 rad,
/// the float rounding itself); results do not depend on the thread count. The exhaustive search
/// leaves out, per block of 4 x 4 x 4 candidates, the points that cannot land in a cell with data
/// from any of them (virtual_sdem.hpp), which changes no cost.
class CorrelationSearch {
 public:
  CorrelationSearch(const Eigen::Matrix3Xd& previous_points, const SphereElevationMap& current,
                    const Eigen::Matrix3d& rotation, const CorrelationOptions& options = {});

  /// Eq. 4 at one candidate; `overlap` receives the shared cells. +inf below min_overlap.
  double cost(const Eigen::Vector3d& translation, std::size_t* overlap = nullptr) const;
  /// Every candidate of the grid; ties go to the first in the grid's order.
  CorrelationResult exhaustive(const TranslationGrid& grid) const;
  /// Coarse to fine: every `coarse`-th candidate along each axis, scored on a coarser S-DEM
  /// (blocks of coarse x coarse cells, the nearest range of each), so
  /// that the cost surface is as smooth as the candidates are sparse; then the `keep` best are
  /// refined within one step on a lattice and a map twice as fine, down to the full grid and
  /// S-DEM. The result says how many candidates were scored. Keeping 16 found the exhaustive
  /// minimum on 12 of 12 simulated pairs (rubble A, B and the corridor, 4 seeds each), keeping
  /// 4 on 8 (a flat valley along a corridor misleads the coarse levels).
  CorrelationResult coarse_to_fine(const TranslationGrid& grid, int coarse = 8, std::size_t keep = 16) const;

  std::size_t points() const { return all_.x.size(); }

 private:
  struct Scratch;
  /// R^T p of the previous points, as three float arrays (the search's layout).
  struct Points {
    std::vector<float> x, y, z;
  };
  /// The search at one resolution: blocks of factor x factor cells and, per block with data
  /// (a slot), the current map's nearest range and eq. 4's weight (every point is projected at
  /// every level: a subset would not see the nearest point of a block that the current map sees).
  struct Level {
    int factor = 1, rows = 0, cols = 0;
    std::vector<int> slot;               ///< per block (+1: outside the grid): its slot, or -1
    std::vector<float> current, weight;  ///< per slot
    std::vector<int> data_sat;           ///< summed-area table of the fine cells whose block has data
  };
  Level make_level(int factor) const;
  /// Eq. 4 at the centre (cx, cy, cz) = R^T t from the given points (R^T p).
  double score(const Level& level, float cx, float cy, float cz, Scratch& scratch, std::size_t* overlap,
               const float* px, const float* py, const float* pz, std::size_t n) const;
  /// Eq. 4 at translation t from every point.
  double score(const Level& level, const Eigen::Vector3d& translation, Scratch& scratch, std::size_t* overlap) const;

  SphereGrid grid_;
  CorrelationOptions options_;
  Eigen::Matrix3d rotation_t_;
  Points all_;                       ///< R^T p, computed once
  std::vector<double> current_map_;  ///< r_cur, NaN where empty
  Level fine_;                       ///< factor 1
};

}  // namespace kiseki
