// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/space_observation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <mutex>
#include <unordered_map>
#include <stdexcept>

#include "kiseki/core/angle.hpp"

namespace kiseki {
namespace {

using Word = std::uint64_t;

// Rows of bits: row y holds cells x = 0..cols-1 in words_per_row words (bit x % 64).
struct BitRows {
  int rows = 0, cols = 0, words = 0;
  std::vector<Word> bits;
  BitRows() = default;
  BitRows(int r, int c) : rows(r), cols(c), words((c + 63) / 64), bits(static_cast<std::size_t>(r) * ((c + 63) / 64), 0) {}
  void set(int x, int y) { bits[static_cast<std::size_t>(y) * words + x / 64] |= Word{1} << (x % 64); }
  const Word* row(int y) const { return bits.data() + static_cast<std::size_t>(y) * words; }
};

struct Rotated {
  BitRows free, occupied;  // in view = free | occupied
  int first_row = 0, last_row = -1;  // rows holding any cell in view
};

// A map's bit rows pre-shifted for every alignment: shifted(s).row(y)[pad + w] holds map cells
// [64 w + s, 64 w + s + 64) of row y (0 outside the map), so a window starting at any column
// reads whole words. `pad` words of zeros on each side let windows hang over the map's edges.
struct ShiftedRows {
  int pad = 0, words = 0, rows = 0;
  std::vector<Word> bits;  // [shift][row][pad + words + pad]
  ShiftedRows() = default;
  ShiftedRows(const BitRows& src, int pad_words) : pad(pad_words), words(src.words), rows(src.rows) {
    const int stride = words + 2 * pad;
    bits.assign(static_cast<std::size_t>(64) * rows * stride, 0);
    for (int sh = 0; sh < 64; ++sh)
      for (int y = 0; y < rows; ++y) {
        const Word* in = src.row(y);
        Word* out = bits.data() + (static_cast<std::size_t>(sh) * rows + y) * stride + pad;
        for (int w = -pad; w < words + pad; ++w) {
          const Word lo = (w >= 0 && w < words) ? in[w] : 0;
          const Word hi = (w + 1 >= 0 && w + 1 < words) ? in[w + 1] : 0;
          out[w] = sh == 0 ? lo : (lo >> sh) | (hi << (64 - sh));
        }
      }
  }
  int stride() const { return words + 2 * pad; }
  // Word k of the window of row y starting at column x0; the next row is stride() words on.
  const Word* window(int y, int x0) const {
    const int sh = ((x0 % 64) + 64) % 64;
    const int q = (x0 - sh) / 64;
    return bits.data() + (static_cast<std::size_t>(sh) * rows + y) * stride() + pad + q;
  }
};

}  // namespace

double SpaceObservationCounts::penetration_ratio() const {
  return map_occupied > 0 ? 100.0 * penetrating / map_occupied : 0.0;
}

double SpaceObservationCounts::intrusion_ratio() const {
  return map_free > 0 ? 100.0 * intruding / map_free : 0.0;
}

void SpaceObservationParams::validate() const {
  if (!(sigma_penetration > 0.0) || !(sigma_intrusion > 0.0) || !(heading_step_deg > 0.0) ||
      heading_step_deg > 45.0 || free_max < 0 || occupied_threshold <= free_max) {
    throw std::invalid_argument(
        "space observation: sigmas and heading step must be positive (step <= 45 deg), "
        "0 <= free_max < occupied_threshold");
  }
  // one pre-rotated local map per heading bin: 3,600 bins at most (1e-9 deg asked for 3.6e11)
  if (heading_step_deg < 0.1) {
    throw std::invalid_argument("space observation: heading_step_deg must be >= 0.1 (3,600 pre-rotated local maps)");
  }
}

struct SpaceObservationModel::Impl {
  SpaceObservationParams params;
  OccupancyGrid map;
  BitRows map_free, map_occupied;
  ShiftedRows shifted_free, shifted_occupied;
  OccupancyGrid local{1, 1, 1.0};
  bool has_local = false;
  int span = 0;  // rotated local maps are span x span map cells, centred on the window cell
  mutable std::vector<Rotated> cache;
  mutable std::mutex visibility_mutex;
  mutable std::unordered_map<long long, std::shared_ptr<const BitRows>> visibility;
  mutable std::vector<std::once_flag> once;  // thread-safe lazy rotation per bin

  Impl(const OccupancyGrid& m, const SpaceObservationParams& p) : params(p), map(m.clone()) {
    map_free = BitRows(m.height(), m.width());
    map_occupied = BitRows(m.height(), m.width());
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) {
        const std::int8_t v = m.value(x, y);
        if (v >= p.occupied_threshold) map_occupied.set(x, y);
        else if (v >= 0 && v <= p.free_max) map_free.set(x, y);
      }
  }

  int bins() const { return static_cast<int>(std::lround(360.0 / params.heading_step_deg)); }

  // The window of a particle: the map cell whose lower-left corner is the grid corner nearest
  // the particle. The local map L has the robot on a cell corner (its origin is at -size/2), so
  // anchoring the window on a corner lines L's cells up with the map's for axis-aligned
  // headings; the particle's snap to that corner is within half a cell either way, zero on
  // average. (Anchoring on the cell that contains the particle treated every particle as
  // sitting on its cell's lower-left corner: a bias of half a cell forward and to the left.)
  CellIndex window_cell(const Pose2& pose) const {
    const Eigen::Vector2d g = map.world_to_grid({pose.x, pose.y});
    const double lim = 1e9;
    return {static_cast<int>(std::floor(std::clamp(g.x() + 0.5, -lim, lim))),
            static_cast<int>(std::floor(std::clamp(g.y() + 0.5, -lim, lim)))};
  }

  void rotate(int bin, Rotated& out) const {
    const double theta = bin * params.heading_step_deg * kPi / 180.0;
    const double c = std::cos(theta), s = std::sin(theta), res = map.resolution();
    out.free = BitRows(span, span);
    out.occupied = BitRows(span, span);
    const double half = 0.5 * local.width() * local.resolution();
    for (int j = 0; j < span; ++j) {
      for (int i = 0; i < span; ++i) {
        // Centre of rotated cell (i, j) relative to the window's corner (the robot), map axes.
        const double dx = (i - span / 2 + 0.5) * res, dy = (j - span / 2 + 0.5) * res;
        const double lx = c * dx + s * dy + half, ly = -s * dx + c * dy + half;  // robot frame
        const int cx = static_cast<int>(std::floor(lx / local.resolution()));
        const int cy = static_cast<int>(std::floor(ly / local.resolution()));
        if (!local.contains(cx, cy)) continue;
        const std::int8_t v = local.value(cx, cy);
        if (v == kFree) out.free.set(i, j);
        else if (v >= params.occupied_threshold) out.occupied.set(i, j);
        else continue;
        if (out.last_row < out.first_row) out.first_row = j;
        out.last_row = j;
      }
    }
  }

  // Cells of the span x span window centred on map cell (cx, cy) that the centre sees: from the
  // centre cell's centre, one segment to the centre of every cell on the window's border, each
  // seeing the cells it passes through up to and including the first occupied one (see the
  // header). The walk is exact, in integers: with (di, dj) the border cell's offset, the segment
  // crosses column boundaries at t = (2m + 1) / (2|di|) and row boundaries at t = (2n + 1) /
  // (2|dj|); scaled by 2 |di| |dj| these are ex = (2m + 1) |dj| and ey = (2n + 1) |di|, so each
  // step compares two integers and a tie is a corner. Along a row (dj = 0) ex stays 0 < ey, and
  // along a column ey stays 0 < ex, so those walk straight.
  std::shared_ptr<const BitRows> visible_from(int cx, int cy) const {
    const long long key = static_cast<long long>(cy) * (1LL << 32) + cx;
    {
      std::lock_guard<std::mutex> lock(visibility_mutex);
      const auto it = visibility.find(key);
      if (it != visibility.end()) return it->second;
    }
    const int half = span / 2;
    const std::size_t cells = static_cast<std::size_t>(span) * span;
    // The window's occupied cells (none outside the map) and the cells seen, one byte each.
    std::vector<std::uint8_t> occupied(cells, 0), seen(cells, 0);
    const int x0 = cx - half, y0 = cy - half;
    for (int j = std::max(0, -y0); j < std::min(span, map.height() - y0); ++j)
      for (int i = std::max(0, -x0); i < std::min(span, map.width() - x0); ++i)
        occupied[static_cast<std::size_t>(j) * span + i] =
            map.value(x0 + i, y0 + j) >= params.occupied_threshold;
    const int centre = half * span + half;
    seen[centre] = 1;
    if (!occupied[centre]) {
      auto walk = [&](int di, int dj) {
        const int ai = std::abs(di), aj = std::abs(dj);
        const int sx = di > 0 ? 1 : -1, sy = dj > 0 ? span : -span;  // index steps
        long long ex = aj, ey = ai;  // next column / row crossing, scaled
        int at = centre;
        for (int left = ai + aj; left > 0;) {
          if (ex < ey) {
            at += sx, ex += 2LL * aj, --left;
          } else if (ey < ex) {
            at += sy, ey += 2LL * ai, --left;
          } else {  // through a corner: both cells touching it are seen; both occupied seal it
            seen[at + sx] = seen[at + sy] = 1;
            if (occupied[at + sx] && occupied[at + sy]) return;
            at += sx + sy, ex += 2LL * aj, ey += 2LL * ai, left -= 2;
          }
          seen[at] = 1;
          if (occupied[at]) return;
        }
      };
      for (int d = -half; d < half; ++d) {  // the border, each cell once
        walk(d, -half);
        walk(half, d);
        walk(-d, half);
        walk(-half, -d);
      }
    }
    auto out = std::make_shared<BitRows>(span, span);
    for (int j = 0; j < span; ++j)
      for (int i = 0; i < span; ++i)
        if (seen[static_cast<std::size_t>(j) * span + i]) out->set(i, j);
    std::lock_guard<std::mutex> lock(visibility_mutex);
    if (visibility.size() > 200000) visibility.clear();  // bound the memory on long runs
    return visibility.emplace(key, std::move(out)).first->second;
  }

  const Rotated& rotated(int bin) const {
    std::call_once(once[bin], [&] { rotate(bin, cache[bin]); });
    return cache[bin];
  }
};

SpaceObservationModel::SpaceObservationModel(const OccupancyGrid& map,
                                             const SpaceObservationParams& params) {
  params.validate();
  impl_ = std::make_unique<Impl>(map, params);
}

SpaceObservationModel::~SpaceObservationModel() = default;
SpaceObservationModel::SpaceObservationModel(SpaceObservationModel&&) noexcept = default;
SpaceObservationModel& SpaceObservationModel::operator=(SpaceObservationModel&&) noexcept = default;

void SpaceObservationModel::set_local_map(const OccupancyGrid& local) {
  if (local.width() != local.height()) throw std::invalid_argument("local map must be square");
  Impl& m = *impl_;
  m.local = local.clone();
  m.has_local = true;
  const double extent = local.width() * local.resolution() * std::sqrt(2.0);
  const int span = static_cast<int>(std::ceil(extent / m.map.resolution())) | 1;  // odd: a centre
  if (span != m.span) {
    std::lock_guard<std::mutex> lock(m.visibility_mutex);
    m.visibility.clear();  // windows of another size
  }
  m.span = span;
  if (m.span > 64 * 64) {
    throw std::invalid_argument("space observation: the local map spans more than 4096 map cells");
  }
  const int pad = (m.span + 63) / 64 + 1;  // words a window may hang over either edge
  if (m.shifted_free.pad < pad) {
    m.shifted_free = ShiftedRows(m.map_free, pad);
    m.shifted_occupied = ShiftedRows(m.map_occupied, pad);
  }
  m.cache = std::vector<Rotated>(static_cast<std::size_t>(m.bins()));
  m.once = std::vector<std::once_flag>(static_cast<std::size_t>(m.bins()));
}

int SpaceObservationModel::bins() const { return impl_->bins(); }

int SpaceObservationModel::bin_of(double heading) const {
  if (!std::isfinite(heading)) throw std::invalid_argument("space observation: heading is not finite");
  const double deg = normalize_angle(heading) * 180.0 / kPi;
  const int n = impl_->bins();
  return ((static_cast<int>(std::lround(deg / impl_->params.heading_step_deg)) % n) + n) % n;
}

SpaceObservationCounts SpaceObservationModel::counts(const Pose2& pose) const {
  const Impl& m = *impl_;
  if (!m.has_local) throw std::logic_error("space observation: set a local map first");
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y)) {
    throw std::invalid_argument("space observation: particle pose is not finite");
  }
  const Rotated& l = m.rotated(bin_of(pose.theta));
  const CellIndex centre = m.window_cell(pose);
  const int x0 = centre.x - m.span / 2, y0 = centre.y - m.span / 2;
  SpaceObservationCounts c;
  const int words = l.free.words;
  // A window further than the padding off the map sees no map cell at all.
  if (x0 + m.span <= 0 || x0 >= m.map.width()) return c;
  const int first = std::max(l.first_row, -y0), last = std::min(l.last_row, m.map.height() - 1 - y0);
  std::shared_ptr<const BitRows> seen;
  if (m.params.occlusion_aware) seen = m.visible_from(centre.x, centre.y);
  Word hidden_free[64];
  if (first > last) return c;
  const int stride = m.shifted_free.stride();
  const Word* occ = m.shifted_occupied.window(y0 + first, x0);
  const Word* fre = m.shifted_free.window(y0 + first, x0);
  for (int j = first; j <= last; ++j, occ += stride, fre += stride) {
    const Word* lf = l.free.row(j);
    const Word* lo = l.occupied.row(j);
    const Word* vis = seen ? seen->row(j) : nullptr;
    for (int k = 0; k < words; ++k) {
      // The expected map: a free cell the sensor cannot see is expected occupied.
      hidden_free[k] = vis ? fre[k] & ~vis[k] : 0;
    }
    for (int k = 0; k < words; ++k) {
      const Word exp_occ = occ[k] | hidden_free[k];
      const Word exp_free = fre[k] & ~hidden_free[k];
      const Word view = lf[k] | lo[k];
      c.penetrating += __builtin_popcountll(lf[k] & exp_occ);
      c.map_occupied += __builtin_popcountll(view & exp_occ);
      c.intruding += __builtin_popcountll(lo[k] & exp_free);
      c.map_free += __builtin_popcountll(view & exp_free);
    }
  }
  return c;
}

double SpaceObservationModel::likelihood(const Pose2& pose) const {
  const SpaceObservationCounts c = counts(pose);
  const double p = c.penetration_ratio() / impl_->params.sigma_penetration;
  const double i = c.intrusion_ratio() / impl_->params.sigma_intrusion;
  return std::exp(-0.5 * (p * p + i * i));
}

void SpaceObservationModel::likelihoods(const double* poses, std::size_t n, double* out) const {
  for (std::size_t k = 0; k < n; ++k) {
    out[k] = likelihood(Pose2(poses[3 * k], poses[3 * k + 1], poses[3 * k + 2]));
  }
}

double SpaceObservationModel::agreement(const Pose2& pose) const {
  const Impl& m = *impl_;
  const CellIndex at = m.map.world_to_cell({pose.x, pose.y});
  if (!m.map.contains(at) || m.map.value(at.x, at.y) < 0 || m.map.value(at.x, at.y) > m.params.free_max) return 0.0;
  const SpaceObservationCounts c = counts(pose);
  if (c.map_occupied == 0) return std::numeric_limits<double>::quiet_NaN();
  return 1.0 - std::min(1.0, static_cast<double>(c.penetrating) / c.map_occupied);
}

void SpaceObservationModel::log_likelihoods(const Pose2* poses, std::size_t n, double* out) const {
  for (std::size_t k = 0; k < n; ++k) out[k] = std::log(likelihood(poses[k]));
}

OccupancyGrid SpaceObservationModel::rotated_local_map(int bin) const {
  const Impl& m = *impl_;
  if (!m.has_local) throw std::logic_error("space observation: set a local map first");
  if (bin < 0 || bin >= m.bins()) throw std::out_of_range("space observation: no such heading bin");
  const Rotated& l = m.rotated(bin);
  OccupancyGrid out(m.span, m.span, m.map.resolution(), Pose2(), kUnknown);
  for (int j = 0; j < m.span; ++j)
    for (int i = 0; i < m.span; ++i) {
      const Word bit = Word{1} << (i % 64);
      if (l.free.row(j)[i / 64] & bit) out.set(i, j, kFree);
      else if (l.occupied.row(j)[i / 64] & bit) out.set(i, j, kOccupied);
    }
  return out;
}

}  // namespace kiseki

namespace kiseki {

OccupancyGrid SpaceObservationModel::visibility(const Pose2& pose) const {
  const Impl& m = *impl_;
  if (!m.has_local) throw std::logic_error("space observation: set a local map first");
  const CellIndex c = m.window_cell(pose);
  const auto seen = m.visible_from(c.x, c.y);
  OccupancyGrid out(m.span, m.span, m.map.resolution(), Pose2(), 0);
  for (int j = 0; j < m.span; ++j)
    for (int i = 0; i < m.span; ++i)
      if (seen->row(j)[i / 64] & (Word{1} << (i % 64))) out.set(i, j, 1);
  return out;
}

}  // namespace kiseki
