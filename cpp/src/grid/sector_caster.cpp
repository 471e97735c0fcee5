// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/sector_caster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>


namespace kiseki {

namespace {
// A jump covers at most this many lines; a longer free run is several jumps (a table of one
// byte per entry: half the memory, and twice the entries in each cache line).
// The entry is 0 at a stopping cell and 1 + J elsewhere, so J is at most 254.
constexpr int kMaxLines = std::numeric_limits<std::uint8_t>::max() - 1;
// Rounding margin on the swept interval's upper end (cells): the slope of a heading is
// computed, and binned, in floating point.
constexpr double kMargin = 1e-6;

// clip_to_box for a point and direction given as numbers, with the direction's reciprocals.
inline bool clip(double px, double py, double dx, double dy, const double* inv, double w, double h,
                 double& t0, double& t1) {
  const double p[2] = {px, py}, d[2] = {dx, dy}, hi[2] = {w, h};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (p[k] < 0.0 || p[k] > hi[k]) return false;
      continue;
    }
    double ta = -p[k] * inv[k], tb = (hi[k] - p[k]) * inv[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

// floor without a library call, for a coordinate that rounding may have put just outside
// the map: clamped to [-2, 2^30] first, so that the conversion is defined.
inline int fast_floor(double v) {
  v = std::clamp(v, -2.0, 1073741824.0);
  const int i = static_cast<int>(v);
  return v < i ? i - 1 : i;
}
}  // namespace

// The summed-area table of the stopping cells: at[y * (w + 1) + x] counts those in columns < x
// and rows < y, so any rectangle's count is four reads.
struct SectorCaster::Prefix {
  std::vector<std::int32_t> at;
  int w;
  int count(int x0, int x1, int y0, int y1) const {  // cells x0..x1 x y0..y1
    const auto row = [&](int y) { return static_cast<std::size_t>(y) * (w + 1); };
    return at[row(y1 + 1) + x1 + 1] - at[row(y0) + x1 + 1] - at[row(y1 + 1) + x0] + at[row(y0) + x0];
  }
};

SectorCaster::SectorCaster(const OccupancyGrid& grid, bool unknown_stops,
                           std::int8_t occupied_threshold, int sectors_per_octant)
    : grid_(grid.clone()), per_octant_(sectors_per_octant), sectors_(8 * sectors_per_octant) {
  if (sectors_per_octant < 1 || sectors_per_octant > 64) {
    throw std::invalid_argument("sector caster: sectors_per_octant must be in 1..64");
  }
  const int w = grid_.width(), h = grid_.height();
  const auto cells = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  std::vector<std::uint8_t> stops(cells);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::int8_t v = grid_.value(x, y);
      stops[static_cast<std::size_t>(y) * w + x] = v >= occupied_threshold || (unknown_stops && v < 0);
    }
  }
  Prefix prefix{std::vector<std::int32_t>(static_cast<std::size_t>(w + 1) * (h + 1), 0), w};
  for (int y = 0; y < h; ++y) {
    std::int32_t in_row = 0;
    for (int x = 0; x < w; ++x) {
      in_row += stops[static_cast<std::size_t>(y) * w + x];
      prefix.at[static_cast<std::size_t>(y + 1) * (w + 1) + x + 1] = prefix.at[static_cast<std::size_t>(y) * (w + 1) + x + 1] + in_row;
    }
  }
  cells_ = cells;
  clear_.assign(cells * static_cast<std::size_t>(sectors_), 0);
  // Each cell's entries depend on the map only: the same table for any number of threads.
#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t c = static_cast<std::size_t>(y) * w + x;
      if (stops[c]) continue;  // 0: the ray ends here
      for (int k = 0; k < sectors_; ++k) clear_[k * cells + c] = 1 + clear_lines(x, y, sector(k), prefix);
    }
  }
}

std::size_t SectorCaster::memory_bytes() const {
  return clear_.size() * sizeof(std::uint8_t);
}

SectorCaster::Sector SectorCaster::sector(int k) const {
  const int octant = k / per_octant_, bin = k % per_octant_;
  return {octant / 4, (octant & 2) ? -1 : 1, (octant & 1) ? -1 : 1,
          static_cast<double>(bin) / per_octant_, static_cast<double>(bin + 1) / per_octant_};
}

std::uint8_t SectorCaster::clear_lines(int cx, int cy, const Sector& s, const Prefix& prefix) const {
  const int n_major = s.axis == 0 ? grid_.width() : grid_.height();
  const int n_minor = s.axis == 0 ? grid_.height() : grid_.width();
  const int major = s.axis == 0 ? cx : cy, minor = s.axis == 0 ? cy : cx;
  // Minor offsets (in the sector's direction) a ray can reach in line j: lo(j) .. hi(j), both
  // growing with j.
  const auto lo = [&](int j) { return static_cast<int>(std::floor(s.slope_lo * std::max(0, j - 1))); };
  const auto hi = [&](int j) { return static_cast<int>(std::floor(1.0 + s.slope_hi * (j + 1) + kMargin)); };
  // Whether line j's cells meet the map (once they leave it, every such ray has left it).
  const auto inside = [&](int j) { return s.minor_step > 0 ? minor + lo(j) < n_minor : minor - lo(j) >= 0; };
  // Whether a stopping cell lies in the bounding box of lines j0..j1's cells.
  const auto blocked = [&](int j0, int j1) {
    const int a = s.minor_step > 0 ? minor + lo(j0) : std::max(minor - hi(j1), 0);
    const int b = s.minor_step > 0 ? std::min(minor + hi(j1), n_minor - 1) : minor - lo(j0);
    const int l0 = major + s.major_step * j0, l1 = major + s.major_step * j1;
    const int m0 = std::min(l0, l1), m1 = std::max(l0, l1);
    return (s.axis == 0 ? prefix.count(m0, m1, a, b) : prefix.count(a, b, m0, m1)) > 0;
  };
  const int limit = std::min(s.major_step > 0 ? n_major - major : major + 1, kMaxLines);
  // Galloping: blocks of 1, 2, 4, ... lines whose box holds no stopping cell are all free; a
  // blocked box is looked at again line by line.
  int j = 0, block = 1;
  while (j < limit) {
    if (!inside(j)) return static_cast<std::uint8_t>(j);
    int end = std::min(j + block, limit) - 1;
    while (end > j && !inside(end)) end = j + (end - j) / 2;
    if (blocked(j, end)) {
      if (end == j) return static_cast<std::uint8_t>(j);
      block = 1;
      continue;
    }
    j = end + 1;
    block *= 2;
  }
  return static_cast<std::uint8_t>(limit);
}

double SectorCaster::range(double x, double y, double heading, double max_range) const {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(heading) || !(max_range >= 0.0)) {
    throw std::invalid_argument("sector caster: start, heading and max_range must be finite");
  }
  const Eigen::Vector2d p = grid_.world_to_grid({x, y});
  const double a = heading - grid_.origin().theta;
  return walk(p.x(), p.y(), std::cos(a), std::sin(a), max_range);
}

double SectorCaster::range_along(double x, double y, double cos_heading, double sin_heading,
                                 double max_range) const {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(cos_heading) || !std::isfinite(sin_heading) ||
      !(max_range >= 0.0)) {
    throw std::invalid_argument("sector caster: start, direction and max_range must be finite");
  }
  const Eigen::Vector2d p = grid_.world_to_grid({x, y});
  // The direction in the grid's frame: rotated by minus the origin's yaw.
  const double co = std::cos(grid_.origin().theta), so = std::sin(grid_.origin().theta);
  return walk(p.x(), p.y(), co * cos_heading + so * sin_heading, co * sin_heading - so * cos_heading, max_range);
}

void SectorCaster::scan(const Pose2& sensor, const double* cos_beam, const double* sin_beam,
                        const double* reach, std::size_t n, double* out) const {
  if (!std::isfinite(sensor.x) || !std::isfinite(sensor.y) || !std::isfinite(sensor.theta)) {
    throw std::invalid_argument("sector caster: the sensor pose must be finite");
  }
  const Eigen::Vector2d p = grid_.world_to_grid({sensor.x, sensor.y});
  const double a = sensor.theta - grid_.origin().theta;
  const double ca = std::cos(a), sa = std::sin(a);
  // kLanes rays walk in turns, one step each: while one waits for its table entry (a cache
  // miss in a table larger than the cache) the others compute. Each ray's walk is walk()'s.
  constexpr int kLanes = 16;
  Ray lanes[kLanes];
  std::size_t beam_of[kLanes];
  std::size_t next_beam = 0;
  const auto fill = [&](int lane) {  // the lane's next unfinished beam; false when none is left
    while (next_beam < n) {
      const std::size_t b = next_beam++;
      if (!(reach[b] >= 0.0) || !std::isfinite(reach[b])) {
        throw std::invalid_argument("sector caster: each beam's reach must be finite and >= 0");
      }
      // The beam's heading theta + angle_b as a rotation of its direction (no trigonometry).
      const double dx = ca * cos_beam[b] - sa * sin_beam[b], dy = sa * cos_beam[b] + ca * sin_beam[b];
      if (start(lanes[lane], p.x(), p.y(), dx, dy, reach[b], out[b])) continue;
      beam_of[lane] = b;
      return true;
    }
    return false;
  };
  bool live[kLanes];
  int walking = 0;
  for (int lane = 0; lane < kLanes; ++lane) walking += live[lane] = fill(lane);
  while (walking > 0) {
    for (int lane = 0; lane < kLanes; ++lane) {
      if (!live[lane] || !advance(lanes[lane], out[beam_of[lane]])) continue;
      if (!(live[lane] = fill(lane))) --walking;
    }
  }
}

double SectorCaster::walk(double px, double py, double dx, double dy, double max_range) const {
  Ray ray;
  double range = max_range;
  if (start(ray, px, py, dx, dy, max_range, range)) return range;
  while (!advance(ray, range)) {
  }
  return range;
}

bool SectorCaster::start(Ray& r, double px, double py, double dx, double dy, double max_range,
                         double& range) const {
  // Reciprocals of the direction (+-inf along an axis): the walk multiplies, as cast_ray divides
  // (equal to rounding).
  r.inv[0] = 1.0 / dx, r.inv[1] = 1.0 / dy;
  const int size[2] = {grid_.width(), grid_.height()};
  double t0 = 0.0;
  r.t1 = max_range / grid_.resolution();
  r.reach = max_range;
  // A start inside the map (a particle's sensor, as a rule) skips the clipping: t0 stays 0, and
  // a ray that leaves the map ends there by the walk's own test, with the same range (the
  // reach) as past the clipped t1.
  const bool inside = px >= 0.0 && py >= 0.0 && px < size[0] && py < size[1];
  if (!inside && !clip(px, py, dx, dy, r.inv, size[0], size[1], t0, r.t1)) {
    range = max_range;
    return true;
  }
  const double ax = std::abs(dx), ay = std::abs(dy);
  r.axis = ax >= ay ? 0 : 1;
  const double slope = r.axis == 0 ? ay * std::abs(r.inv[0]) : ax * std::abs(r.inv[1]);
  const int octant = r.axis == 0 ? (dx < 0 ? 2 : 0) + (dy < 0 ? 1 : 0) : 4 + (dy < 0 ? 2 : 0) + (dx < 0 ? 1 : 0);
  const int k = octant * per_octant_ + std::min(static_cast<int>(slope * per_octant_), per_octant_ - 1);
  r.table = clear_.data() + static_cast<std::size_t>(k) * cells_;
  r.pos[0] = px, r.pos[1] = py, r.dir[0] = dx, r.dir[1] = dy;
  r.step[0] = dx > 0 ? 1 : -1, r.step[1] = dy > 0 ? 1 : -1;
  r.dt[0] = std::abs(r.inv[0]), r.dt[1] = std::abs(r.inv[1]);
  r.c[0] = std::clamp(fast_floor(px + t0 * dx), 0, size[0] - 1);
  r.c[1] = std::clamp(fast_floor(py + t0 * dy), 0, size[1] - 1);
  r.t = t0;
  enter(r);
  return false;
}

void SectorCaster::enter(Ray& r) const {
  // t at which the ray crosses the next vertical / horizontal cell boundary
  for (int i = 0; i < 2; ++i) {
    r.next[i] = r.dir[i] != 0.0 ? ((r.c[i] + (r.step[i] > 0 ? 1 : 0)) - r.pos[i]) * r.inv[i]
                                : std::numeric_limits<double>::infinity();
  }
  r.cell = static_cast<std::size_t>(r.c[1]) * grid_.width() + r.c[0];
  __builtin_prefetch(r.table + r.cell);
}

bool SectorCaster::advance(Ray& r, double& range) const {
  const int size[2] = {grid_.width(), grid_.height()};
  const int entry = r.table[r.cell];
  if (entry == 0) {  // a stopping cell
    range = r.t * grid_.resolution();
    return true;
  }
  const int lines = entry - 1;
  const int A = r.axis, B = 1 - r.axis;
  if (lines >= 2) {  // lines c .. c + lines - 1 are free for this ray: enter line `lines`
    const int line = r.c[A] + r.step[A] * lines;
    const double t_line = ((r.step[A] > 0 ? line : line + 1) - r.pos[A]) * r.inv[A];
    const int across = fast_floor(r.pos[B] + t_line * r.dir[B]);
    // past the reach, or the ray left the map on the way
    if (t_line > r.t1 || line < 0 || line >= size[A] || across < 0 || across >= size[B]) {
      range = r.reach;
      return true;
    }
    r.t = t_line, r.c[A] = line, r.c[B] = across;
    enter(r);
    return false;
  }
  const int i = r.next[0] < r.next[1] ? 0 : 1;  // Amanatides and Woo's step to the next cell
  r.t = r.next[i];
  r.next[i] += r.dt[i];
  r.c[i] += r.step[i];
  if (r.t > r.t1 || r.c[i] < 0 || r.c[i] >= size[i]) {
    range = r.reach;
    return true;
  }
  r.cell = static_cast<std::size_t>(r.c[1]) * size[0] + r.c[0];
  __builtin_prefetch(r.table + r.cell);
  return false;
}

}  // namespace kiseki
