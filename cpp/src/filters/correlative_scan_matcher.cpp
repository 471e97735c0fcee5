// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/correlative_scan_matcher.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/models/scan_beams.hpp"

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
  if (threads < 0) throw std::invalid_argument("correlative matcher: threads must be >= 0");
}

CorrelativeScanMatcher::CorrelativeScanMatcher(const OccupancyGrid& map, double max_range,
                                               const CorrelativeMatcherParams& params)
    : params_((params.validate(), params)), max_range_(max_range), frame_(map.clone()) {
  if (!(max_range > 0.0) || !std::isfinite(max_range)) {
    throw std::invalid_argument("correlative matcher: max_range must be finite and > 0");
  }
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

struct Leaf {
  double score;
  std::int64_t index;  // (heading * height + y) * width + x
  int x, y, k;
  Pose2 pose;
};

bool before(const Leaf& a, const Leaf& b) { return a.score > b.score || (a.score == b.score && a.index < b.index); }

}  // namespace

int CorrelativeScanMatcher::headings(const double* angles, const float* ranges, std::size_t n) const {
  const ScanBeams beams = used_beams(angles, ranges, n, max_range_, params_.likelihood.max_beams);
  return heading_count(beams, frame_.resolution(), params_.angular_step);
}

/// One search: the rotated scans' cell offsets, the shared threshold and its witnesses (a set of
/// pairwise far poses found), and per worker the leaves it found.
struct CorrelativeScanMatcher::Search {
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
  bool on_side(int level, int x, int y, int k) const {
    if (disc == nullptr) return true;
    const int last = (1 << level) - 1;
    const double px = disc_x[static_cast<std::size_t>(k)], py = disc_y[static_cast<std::size_t>(k)];
    if (disc->inside) {
      const double ex = std::max({x - px, 0.0, px - (x + last)}), ey = std::max({y - py, 0.0, py - (y + last)});
      return std::hypot(ex, ey) <= disc_radius + 1e-6;
    }
    const double fx = std::max(std::abs(px - x), std::abs(px - (x + last)));
    const double fy = std::max(std::abs(py - y), std::abs(py - (y + last)));
    return std::hypot(fx, fy) > disc_radius - 1e-6;
  }

  bool kept(const Pose2& p) const {
    if (disc == nullptr) return true;
    const bool in = std::hypot(p.x - disc->x, p.y - disc->y) <= disc->radius;
    return in == disc->inside;
  }

  bool close(const Pose2& a, const Pose2& b, double scale) const {
    return std::hypot(a.x - b.x, a.y - b.y) < scale * m.params_.min_distance &&
           std::abs(normalize_angle(a.theta - b.theta)) < scale * m.params_.min_angle;
  }

  void raise(double t) {
    double cur = threshold.load();
    while (t > cur && !threshold.compare_exchange_weak(cur, t)) {
    }
  }

  void leaf(Worker& w, double score, int x, int y, int k) {
    if (score < threshold.load()) return;
    const int width = m.frame_.width(), height = m.frame_.height();
    Leaf l{score, (static_cast<std::int64_t>(k) * height + y) * width + x, x, y, k, m.lattice_pose(x, y, k, headings)};
    if (!kept(l.pose)) return;
    w.leaves.push_back(l);
    // Keep k found poses pairwise "far" (2 min_distance or 2 min_angle apart), trading a member
    // for a better pose when that keeps them far; their lowest score bounds the k-th result.
    const auto kk = static_cast<std::size_t>(m.params_.hypotheses);
    std::lock_guard<std::mutex> lock(far_mutex);
    std::size_t near = far.size(), count = 0;
    for (std::size_t i = 0; i < far.size(); ++i) {
      if (close(far[i].pose, l.pose, 2.0)) near = i, ++count;
    }
    if (count == 0 && far.size() < kk) {
      far.push_back(l);
    } else if (count == 0 || count == 1) {
      if (count == 0) {
        near = static_cast<std::size_t>(std::min_element(far.begin(), far.end(), [](const Leaf& a, const Leaf& b) {
                                          return a.score < b.score;
                                        }) - far.begin());
      }
      if (score > far[near].score) far[near] = l;
    }
    if (far.size() == kk) {
      double lowest = far[0].score;
      for (const auto& f : far) lowest = std::min(lowest, f.score);
      raise(lowest);
    }
    if (w.leaves.size() >= 2 * w.compacted + 4096) {
      const double t = threshold.load();
      w.leaves.erase(std::remove_if(w.leaves.begin(), w.leaves.end(), [t](const Leaf& a) { return a.score < t; }),
                     w.leaves.end());
      w.compacted = w.leaves.size();
    }
  }

  // Hess et al. Algorithm 3: depth first, children in order of their bounds.
  void descend(Worker& w, int level, int x, int y, int k, double b) {
    if (b < threshold.load()) return;
    if (level == 0) return leaf(w, b, x, y, k);
    const int half = 1 << (level - 1);
    std::tuple<double, int, int> kids[4];
    int n = 0;
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        const int cx = x + i * half, cy = y + j * half;
        if (cx >= m.frame_.width() || cy >= m.frame_.height() || !m.has_free(level - 1, cx, cy) ||
            !on_side(level - 1, cx, cy, k)) {
          continue;
        }
        kids[n++] = {bound(level - 1, cx, cy, k), cx, cy};
      }
    }
    for (int i = 1; i < n; ++i) {  // best bound first, equal bounds in their order (a stable sort)
      for (int j = i; j > 0 && std::get<0>(kids[j]) > std::get<0>(kids[j - 1]); --j) std::swap(kids[j], kids[j - 1]);
    }
    for (int i = 0; i < n; ++i) descend(w, level - 1, std::get<1>(kids[i]), std::get<2>(kids[i]), k, std::get<0>(kids[i]));
  }
};

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
  std::vector<Leaf> all;
  for (auto& wk : workers) all.insert(all.end(), wk.leaves.begin(), wk.leaves.end());
  std::sort(all.begin(), all.end(), before);
  std::vector<PoseHypothesis> out;
  for (const Leaf& l : all) {
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
