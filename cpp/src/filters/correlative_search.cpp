// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The correlative matcher's search: which nodes it keeps and how it descends (Hess et al. 2016,
// sec. V.C and Algorithm 3).
#include "correlative_search.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "kiseki/core/angle.hpp"

namespace kiseki {

bool CorrelativeScanMatcher::Search::on_side(int level, int x, int y, int k) const {
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

bool CorrelativeScanMatcher::Search::kept(const Pose2& p) const {
  if (disc == nullptr) return true;
  const bool in = std::hypot(p.x - disc->x, p.y - disc->y) <= disc->radius;
  return in == disc->inside;
}

bool CorrelativeScanMatcher::Search::close(const Pose2& a, const Pose2& b, double scale) const {
  return std::hypot(a.x - b.x, a.y - b.y) < scale * m.params_.min_distance &&
         std::abs(normalize_angle(a.theta - b.theta)) < scale * m.params_.min_angle;
}

void CorrelativeScanMatcher::Search::raise(double t) {
  double cur = threshold.load();
  while (t > cur && !threshold.compare_exchange_weak(cur, t)) {
  }
}

void CorrelativeScanMatcher::Search::leaf(Worker& w, double score, int x, int y, int k) {
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

void CorrelativeScanMatcher::Search::descend(Worker& w, int level, int x, int y, int k, double b) {
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

}  // namespace kiseki
