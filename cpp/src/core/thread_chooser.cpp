// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/thread_chooser.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace kiseki {

ThreadChooser::ThreadChooser(int most, int probe_every) : most_(most), probe_every_(probe_every), next_(most) {
  if (most < 1) throw std::invalid_argument("ThreadChooser: most must be >= 1");
  if (probe_every < 2) throw std::invalid_argument("ThreadChooser: probe_every must be >= 2");
}

double ThreadChooser::cost(int k) const {
  const int n = std::min(count_[k], kKept);
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  std::array<double, kKept> v = kept_[k];
  std::nth_element(v.begin(), v.begin() + n / 2, v.begin() + n);
  return v[n / 2];
}

void ThreadChooser::record(double seconds, std::size_t items) {
  if (most_ == 1) return;
  const int k = next_ == 1 ? 0 : 1;
  if (!warmed_[k]) {
    warmed_[k] = true;  // the choice's first step: not typical of it
  } else if (std::isfinite(seconds) && seconds >= 0.0) {
    kept_[k][count_[k] % kKept] = seconds / static_cast<double>(std::max<std::size_t>(items, 1));
    ++count_[k];
  }
  if (count_[0] < kFirst || count_[1] < kFirst) {  // the first steps: the two in turn
    next_ = k == 1 ? 1 : most_;
    return;
  }
  const double one = cost(0), all = cost(1);
  const int best = one <= all ? 1 : most_;
  const double ratio = std::max(one, all) / std::max(std::min(one, all), 1e-300);
  const double interval = static_cast<double>(probe_every_) * std::min(ratio, 1e6);
  if (++since_probe_ >= interval) {
    since_probe_ = 0;
    next_ = best == 1 ? most_ : 1;
  } else {
    next_ = best;
  }
}

}  // namespace kiseki
