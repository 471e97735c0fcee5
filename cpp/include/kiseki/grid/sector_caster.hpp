// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// The ray casters a model can use for its expected ranges; both equal cast_ray's to rounding.
/// distance_field: RangeCaster (a distance field, 4 bytes per cell); swept_sector: SectorCaster
/// (a table of 64 bytes per cell, built once per map, faster per ray).
enum class RayCasterKind { distance_field, swept_sector };

/// Exact ranges along rays in a grid, faster than RangeCaster for a beam model: a swept-sector
/// clearance table computed once per map lets a ray jump over the free lines of cells ahead
/// of it, and the Amanatides and Woo cell walk (as cast_ray) resumes before the first line
/// that could stop it. The result equals cast_ray's to rounding, as RangeCaster's does.
///
/// The headings are cut into 8 octants (the major axis of travel, x or y, its sign, and the
/// sign of the minor axis) and each octant into `sectors_per_octant` equal slope intervals
/// [i/s, (i+1)/s] of |minor| / |major|. For a cell c and a sector k the table holds J(c, k): how
/// many lines of cells across the major axis (columns for an x-major sector, rows for a
/// y-major one) every ray from anywhere in c with a heading in k crosses without meeting a
/// stopping cell. A ray from a point (u0, v0) of c, u0, v0 in [0, 1] in the sector's frame, with
/// slope m in [m_lo, m_hi], lies within line j at minor offsets v0 + m (u - u0), u - u0 in
/// [max(0, j - 1), j + 1]: the cells [floor(m_lo max(0, j - 1)), floor(1 + m_hi (j + 1))] of
/// line j. A summed-area table of the stopping cells answers whether any cell of a box of
/// lines holds one, so the lines are looked at in galloping blocks (1, 2, 4, ... lines).
/// J(c, k) is the first line that holds one, or leaves the map; the walk jumps to where the
/// ray enters line J (when J >= 2) and looks again from the cell it lands in. No cell it
/// passes over can stop it, so it meets the same first stopping cell as the cell walk.
///
/// What stops a ray is nav2's rule (as RangeCaster): an occupied cell (>= threshold), an
/// unknown cell when unknown_stops, and the edge of the map. Memory: 1 byte per cell and
/// sector (8 x sectors_per_octant sectors), holding 0 at a stopping cell and 1 + J elsewhere
/// (J capped at 254 lines: a longer free run is several jumps); the summed-area table, 4 bytes
/// per cell, lives only while the table is built.
class SectorCaster {
 public:
  SectorCaster(const OccupancyGrid& grid, bool unknown_stops = true,
               std::int8_t occupied_threshold = 65, int sectors_per_octant = 8);
  /// Range from a world point along a world heading to the first stopping cell, at most
  /// max_range.
  double range(double x, double y, double heading, double max_range) const;
  /// The same along a unit direction (cos, sin of the world heading) given by the caller.
  double range_along(double x, double y, double cos_heading, double sin_heading,
                     double max_range) const;
  /// A scan from one sensor pose: beam b leaves it at heading sensor.theta + angle_b, given as
  /// cos and sin of angle_b (sensor frame), and reaches at most reach[b]. Writes n ranges to
  /// out. The heading is a rotation of the beam's direction: one sine and cosine per scan. The
  /// rays walk 16 at a time in turns, so that one ray's cache miss in the table overlaps the
  /// others' work; each ray's result is its own walk's.
  void scan(const Pose2& sensor, const double* cos_beam, const double* sin_beam,
            const double* reach, std::size_t n, double* out) const;
  const OccupancyGrid& grid() const { return grid_; }
  int sectors() const { return sectors_; }
  /// Bytes held by the table (what the caster adds to its copy of the map's cells).
  std::size_t memory_bytes() const;

 private:
  struct Sector {
    int axis;                    // 0: x is the major axis, 1: y
    int major_step, minor_step;  // +1 or -1
    double slope_lo, slope_hi;   // |minor| / |major| of the sector's headings
  };
  Sector sector(int k) const;
  struct Prefix;
  std::uint8_t clear_lines(int cx, int cy, const Sector& s, const Prefix& prefix) const;
  // One ray's walk in grid units, as a state that advances a cell or a jump at a time.
  struct Ray {
    double pos[2], dir[2], inv[2], dt[2], next[2];
    double t, t1, reach;
    int c[2], step[2], axis;
    std::size_t cell;
    const std::uint8_t* table;  // the layer of the ray's sector
  };
  double walk(double px, double py, double dx, double dy, double max_range) const;
  // Sets a ray up; true (and range) when it is done before a step (it misses the map).
  bool start(Ray& r, double px, double py, double dx, double dy, double max_range, double& range) const;
  void enter(Ray& r) const;  // the cell boundaries and table entry of the cell r.c
  // One step (a jump or a cell); true, and range, when the ray has ended.
  bool advance(Ray& r, double& range) const;

  OccupancyGrid grid_;
  int per_octant_, sectors_;
  std::size_t cells_ = 0;
  // At k * cells_ + c: 0 when c stops a ray, else 1 + J(c, k); one map-sized layer a sector
  std::vector<std::uint8_t> clear_;
};

}  // namespace kiseki
