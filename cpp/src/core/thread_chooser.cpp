// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/thread_chooser.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kiseki {

ThreadChooser::ThreadChooser(int most, int probe_every, double smoothing)
    : most_(most), probe_every_(probe_every), smoothing_(smoothing), next_(most) {
  if (most < 1) throw std::invalid_argument("ThreadChooser: most must be >= 1");
  if (probe_every < 2) throw std::invalid_argument("ThreadChooser: probe_every must be >= 2");
  if (!(smoothing > 0.0 && smoothing <= 1.0)) throw std::invalid_argument("ThreadChooser: smoothing must be in (0, 1]");
  cost_[0] = cost_[1] = std::numeric_limits<double>::quiet_NaN();
}

void ThreadChooser::record(double seconds, std::size_t items) {
  if (most_ == 1) return;
  const int k = next_ == 1 ? 0 : 1;
  if (!warmed_[k]) {
    warmed_[k] = true;  // the choice's first step: not typical of it
  } else if (std::isfinite(seconds) && seconds >= 0.0) {
    // A probe replaces its choice's average: made probe_every steps ago, it is stale.
    const double per_item = seconds / static_cast<double>(std::max<std::size_t>(items, 1));
    cost_[k] = std::isnan(cost_[k]) || probing_ ? per_item : cost_[k] + smoothing_ * (per_item - cost_[k]);
  }
  // Each choice measured before any is preferred; then the cheaper, and now and then the other.
  probing_ = false;
  if (std::isnan(cost_[1])) {
    next_ = most_;
  } else if (std::isnan(cost_[0])) {
    next_ = 1;
  } else {
    const int best = cost_[0] <= cost_[1] ? 1 : most_;
    if (++since_probe_ >= probe_every_) since_probe_ = 0, probing_ = true;
    next_ = probing_ ? (best == 1 ? most_ : 1) : best;
  }
}

}  // namespace kiseki
