// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/terrain/sphere_elevation_map.hpp"

namespace kiseki {

/// The constants for projecting points onto the cells of an S-DEM seen from a candidate centre
/// (paper 003 eq. 3, the virtual S-DEM): the grid's lower edges (rad), its cells per rad and
/// extent in cells, and a level of factor x factor blocks of cells (factor 1: the S-DEM itself).
struct CellProjection {
  float th_edge = 0, ph_edge = 0, inv = 0, rows = 0, cols = 0;
  float inv_factor = 1;  ///< 1 / factor
  int level_cols = 0;
  float max_r2 = 0;
  int outside = 0;  ///< the cell of points outside the grid or at or beyond max_range
  CellProjection(const SphereGrid& grid, int factor, int level_rows, int level_cols);
};

/// Eq. 3 for points q = p - c (p: three float arrays of n, c the candidate centre): each point's
/// cell (theta row, phi column, through a polynomial arctangent in float arithmetic, error
/// below 2e-7 rad; `outside` beyond the grid or max_range) and its range. Branch-free
/// and vectorised (AVX-512 or AVX2 where the CPU has them, with the same results: the file is
/// compiled without contraction to fused multiply-adds).
void project_points(const float* px, const float* py, const float* pz, std::size_t n, float cx, float cy,
                    float cz, const CellProjection& projection, int* cell_of, float* range_of);

/// The points that may land in a cell with data from some centre within `rho` of (cx, cy, cz):
/// a point q0 = p - c0 moves by at most rho, so its direction turns by at most asin(rho / |q0|)
/// (phi, a latitude, by no more) and its theta, an angle in the x-z plane, by at most
/// asin(rho / |q0_xz|). `data_sat` is the summed-area table ((rows + 1) x (cols + 1)) of the
/// grid's cells with data; a point whose widened rectangle of cells holds none, or that stays at
/// or beyond max_range, cannot change eq. 4 there and is left out. Writes the kept points' indices
/// in their order to `kept` (room for n) and returns how many; `scratch` is resized as needed.
std::size_t points_that_may_land(const float* px, const float* py, const float* pz, std::size_t n, double cx,
                                 double cy, double cz, double rho, const SphereGrid& grid,
                                 const std::vector<int>& data_sat, std::vector<int>& scratch,
                                 std::uint32_t* kept);

/// Eq. 4's sums over the slots of the cells with data, given the virtual map's nearest range
/// per slot (+inf where no point landed): sum of (r_v - r_cur)^2 w, sum of w, and the slots
/// with a point. `slots` is a multiple of 8; slot j adds to lane j % 8 of the sums and the lanes
/// are added last, so the result does not depend on the thread count. Resets the slots to +inf.
struct Eq4Sums {
  double sum = 0, weights = 0;
  std::size_t shared = 0;
};
Eq4Sums eq4_sums(float* zbuffer, const float* current, const float* weight, std::size_t slots);

}  // namespace kiseki
