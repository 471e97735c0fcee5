// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/correlative_scan_matcher.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/models/scan_beams.hpp"

#include "correlative_search.hpp"

namespace kiseki {

void CorrelativeMatcherParams::validate() const {
  likelihood.validate();
  if (depth < 0 || depth > 16) throw std::invalid_argument("correlative matcher: depth must be in 0..16");
  if (!(angular_step >= 0.0) || !std::isfinite(angular_step)) {
    throw std::invalid_argument("correlative matcher: angular_step must be finite and >= 0");
  }
  if (hypotheses < 1) throw std::invalid_argument("correlative matcher: hypotheses must be >= 1");
  if (!(min_distance >= 0.0) || !std::isfinite(min_distance) || !(min_angle >= 0.0) || !std::isfinite(min_angle)) {
    throw std::invalid_argument("correlative matcher: min_distance and min_angle must be finite and >= 0");
  }
  check_threads(threads, "correlative matcher");
}

CorrelativeScanMatcher::CorrelativeScanMatcher(const OccupancyGrid& map, double max_range,
                                               const CorrelativeMatcherParams& params)
    : params_((params.validate(), params)), max_range_(max_range), frame_(map.clone()) {
  if (!(max_range > 0.0) || !std::isfinite(max_range)) {
    throw std::invalid_argument("correlative matcher: max_range must be finite and > 0");
  }
  // A node of the coarsest level that covers the whole map ends the search's levels: a deeper
  // one adds a level of the padded layout each (memory (depth + 1) (w + 2^depth) (h + 2^depth)
  // x 5 bytes, 366 GB at depth 16 on an 80 x 80 map) and the same best poses.
  int covering = 0;
  while ((1 << covering) < std::max(map.width(), map.height())) ++covering;
  params_.depth = std::min(params_.depth, covering);
  // The score table is the likelihood field's own (Probabilistic Robotics, Table 6.3).
  LikelihoodFieldModel field(map, params_.likelihood);
  field.set_scan(nullptr, nullptr, 0, max_range);
  outside_ = field.outside();
  const int w = map.width(), h = map.height();
  const cv::Mat& table = field.table();
  // P_h(x, y) = max of P_{h-1} over the 2 x 2 blocks of side 2^(h-1) starting at (x, y)
  // (Hess et al. sec. V.C). Every level is stored on one padded layout, from x = y = -(2^depth
  // - 1), where the coarsest window first meets the map: a beam end is then one linear offset
  // from a node at every level. A window that does not meet the map holds outside_ (no free
  // cell), as the level below reads it.
  const int pad = (1 << params_.depth) - 1;
  pitch_ = w + pad, rows_ = h + pad;
  const std::size_t cells = static_cast<std::size_t>(pitch_) * rows_;
  pooled_.assign(static_cast<std::size_t>(params_.depth) + 1, std::vector<float>(cells, outside_));
  free_.assign(pooled_.size(), std::vector<std::uint8_t>(cells, 0));
  magnitude_ = std::abs(outside_);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = index(x, y);
      pooled_[0][i] = table.ptr<float>(y)[x];
      free_[0][i] = !params_.free_only || is_free(map.value(x, y));
      magnitude_ = std::max(magnitude_, static_cast<double>(std::abs(pooled_[0][i])));
    }
  }
  if (lattice_cells() == 0) throw std::invalid_argument("correlative matcher: the map has no free cell to search");
  for (int level = 1; level <= params_.depth; ++level) {
    const int half = 1 << (level - 1);
    auto& out = pooled_[static_cast<std::size_t>(level)];
    auto& any = free_[static_cast<std::size_t>(level)];
    for (int y = -((1 << level) - 1); y < h; ++y) {
      for (int x = -((1 << level) - 1); x < w; ++x) {
        const std::size_t i = index(x, y);
        out[i] = std::max(std::max(value(level - 1, x, y), value(level - 1, x + half, y)),
                          std::max(value(level - 1, x, y + half), value(level - 1, x + half, y + half)));
        any[i] = has_free(level - 1, x, y) || has_free(level - 1, x + half, y) || has_free(level - 1, x, y + half) ||
                 has_free(level - 1, x + half, y + half);
      }
    }
  }
}

std::size_t CorrelativeScanMatcher::index(int x, int y) const {
  const int pad = pitch_ - frame_.width();
  return static_cast<std::size_t>(y + pad) * static_cast<std::size_t>(pitch_) + static_cast<std::size_t>(x + pad);
}

float CorrelativeScanMatcher::value(int level, int x, int y) const {
  const int pad = pitch_ - frame_.width();
  if (x < -pad || y < -pad || x >= frame_.width() || y >= frame_.height()) return outside_;
  return pooled_[static_cast<std::size_t>(level)][index(x, y)];
}

bool CorrelativeScanMatcher::has_free(int level, int x, int y) const {
  const int pad = pitch_ - frame_.width();
  if (x < -pad || y < -pad || x >= frame_.width() || y >= frame_.height()) return false;
  return free_[static_cast<std::size_t>(level)][index(x, y)] != 0;
}

std::size_t CorrelativeScanMatcher::lattice_cells() const {
  return static_cast<std::size_t>(std::count(free_[0].begin(), free_[0].end(), std::uint8_t{1}));
}

Pose2 CorrelativeScanMatcher::lattice_pose(int cell_x, int cell_y, int heading, int headings) const {
  if (headings < 1) throw std::invalid_argument("correlative matcher: headings must be >= 1");
  const double r = frame_.resolution();
  const Pose2 sensor_in_grid((cell_x + 0.5) * r, (cell_y + 0.5) * r, heading * (2.0 * kPi / headings));
  return frame_.origin().compose(sensor_in_grid).compose(params_.likelihood.sensor.inverse());
}

namespace {

ScanBeams used_beams(const double* angles, const float* ranges, std::size_t n, double max_range, int max_beams) {
  ScanBeams beams;
  beams.set(angles, ranges, n, max_range, max_beams, /*keep_no_return=*/false);
  return beams;
}

int heading_count(const ScanBeams& beams, double resolution, double angular_step) {
  if (beams.size() == 0) return 0;
  double step = angular_step;
  if (step == 0.0) {
    // Hess et al. eq. (7): the farthest end moves by at most one cell between headings.
    const double d = *std::max_element(beams.range.begin(), beams.range.end()) / resolution;
    step = d <= 0.5 ? kPi / 2 : std::acos(1.0 - 1.0 / (2.0 * d * d));
  }
  return std::max(1, static_cast<int>(std::ceil(2.0 * kPi / step - 1e-9)));
}

}  // namespace

int CorrelativeScanMatcher::headings(const double* angles, const float* ranges, std::size_t n) const {
  const ScanBeams beams = used_beams(angles, ranges, n, max_range_, params_.likelihood.max_beams);
  return heading_count(beams, frame_.resolution(), params_.angular_step);
}

std::vector<PoseHypothesis> CorrelativeScanMatcher::match(const double* angles, const float* ranges,
                                                          std::size_t n, const SearchDisc* disc) const {
  const ScanBeams beams = used_beams(angles, ranges, n, max_range_, params_.likelihood.max_beams);
  Search s(*this);
  s.headings = heading_count(beams, frame_.resolution(), params_.angular_step);
  s.beams = static_cast<int>(beams.size());
  if (s.beams == 0) return {};
  // Each heading is one rotated scan, its ends rounded to cell offsets from the laser's cell
  // (the laser at a cell centre, as LikelihoodFieldModel reads the end cells).
  const double inv_res = 1.0 / frame_.resolution();
  s.dx.resize(static_cast<std::size_t>(s.headings) * s.beams);
  s.dy.resize(s.dx.size());
  s.off.resize(s.dx.size());
  for (int k = 0; k < s.headings; ++k) {
    const double th = normalize_angle(k * (2.0 * kPi / s.headings));
    const double c = std::cos(th), sn = std::sin(th);
    for (int b = 0; b < s.beams; ++b) {
      const double bx = beams.range[b] * beams.cos[b] * inv_res, by = beams.range[b] * beams.sin[b] * inv_res;
      const std::size_t i = static_cast<std::size_t>(k) * s.beams + b;
      s.dx[i] = static_cast<int>(std::floor(0.5 + (c * bx - sn * by)));
      s.dy[i] = static_cast<int>(std::floor(0.5 + (sn * bx + c * by)));
      s.off[i] = static_cast<std::ptrdiff_t>(s.dy[i]) * pitch_ + s.dx[i];
    }
  }
  s.margin = 2.0 * static_cast<double>(s.beams) * s.beams * std::ldexp(magnitude_, -53);
  if (disc != nullptr) {
    if (!(disc->radius >= 0.0) || !std::isfinite(disc->radius) || !std::isfinite(disc->x) || !std::isfinite(disc->y)) {
      throw std::invalid_argument("correlative matcher: a search disc needs a finite centre and radius >= 0");
    }
    s.disc = disc;
    s.disc_radius = disc->radius * inv_res;
    const Pose2 to_grid = frame_.origin().inverse(), offset = params_.likelihood.sensor.inverse();
    s.disc_x.resize(static_cast<std::size_t>(s.headings));
    s.disc_y.resize(s.disc_x.size());
    for (int k = 0; k < s.headings; ++k) {
      // robot = laser + R(theta) * offset, so |robot - c| = |laser - (c - R(theta) * offset)|
      const double th = frame_.origin().theta + k * (2.0 * kPi / s.headings);
      const Eigen::Vector2d c(disc->x - (std::cos(th) * offset.x - std::sin(th) * offset.y),
                              disc->y - (std::sin(th) * offset.x + std::cos(th) * offset.y));
      const Eigen::Vector2d g = to_grid.transform_point(c) * inv_res;
      s.disc_x[static_cast<std::size_t>(k)] = g.x() - 0.5, s.disc_y[static_cast<std::size_t>(k)] = g.y() - 0.5;
    }
  }
  // The coarsest nodes, scored in parallel and visited best bound first.
  const int top = params_.depth, side = 1 << top, w = frame_.width(), h = frame_.height();
  const int nx = (w + side - 1) / side, ny = (h + side - 1) / side;
  struct Node {
    double bound;
    std::int64_t index;
  };
  std::vector<Node> nodes(static_cast<std::size_t>(nx) * ny * s.headings);
  const auto node_cell = [&](std::int64_t i, int& x, int& y, int& k) {
    x = static_cast<int>(i % nx) * side, y = static_cast<int>((i / nx) % ny) * side, k = static_cast<int>(i / (nx * ny));
  };
  parallel_for(nodes.size(), params_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      int x, y, k;
      node_cell(static_cast<std::int64_t>(i), x, y, k);
      // a node without a free cell is not searched (index -1)
      nodes[i] = has_free(top, x, y) && s.on_side(top, x, y, k) ? Node{s.bound(top, x, y, k), static_cast<std::int64_t>(i)} : Node{0.0, -1};
    }
  }, 64);
  nodes.erase(std::remove_if(nodes.begin(), nodes.end(), [](const Node& n) { return n.index < 0; }), nodes.end());
  std::sort(nodes.begin(), nodes.end(), [](const Node& a, const Node& b) {
    return a.bound > b.bound || (a.bound == b.bound && a.index < b.index);
  });
  // Workers take the next node of that order as they come free; they share only the (safe)
  // threshold, so which worker searches which node does not change the result.
  const std::size_t t = std::min<std::size_t>(static_cast<std::size_t>(resolve_threads(params_.threads)), nodes.size());
  std::vector<Search::Worker> workers(t);
  std::atomic<std::size_t> next{0};
  parallel_for(t, params_.threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t wi = begin; wi < end; ++wi) {
      for (std::size_t i = next++; i < nodes.size(); i = next++) {
        int x, y, k;
        node_cell(nodes[i].index, x, y, k);
        s.descend(workers[wi], top, x, y, k, nodes[i].bound);
      }
    }
  }, 1);
  // The greedy selection over the leaves kept, which hold every pose it can take.
  std::vector<Search::Leaf> all;
  for (auto& wk : workers) all.insert(all.end(), wk.leaves.begin(), wk.leaves.end());
  std::sort(all.begin(), all.end(), Search::before);
  std::vector<PoseHypothesis> out;
  for (const Search::Leaf& l : all) {
    if (out.size() == static_cast<std::size_t>(params_.hypotheses)) break;
    const bool taken = std::any_of(out.begin(), out.end(), [&](const PoseHypothesis& o) { return s.close(o.pose, l.pose, 1.0); });
    if (!taken) out.push_back({l.pose, l.score, l.x, l.y, l.k});
  }
  if (params_.likelihood.combination == BeamCombination::nav2) {
    for (auto& o : out) o.score = std::log1p(o.score);
  }
  return out;
}

}  // namespace kiseki
