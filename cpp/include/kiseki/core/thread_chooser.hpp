// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>

namespace kiseki {

/// Chooses, step by step, between one thread and every core for loops whose results do not
/// depend on the thread count (the choice changes the time only), from the measured time of
/// the steps made with each. On a free machine every core is faster; on one whose cores other
/// processes keep busy (a robot's planner, a second localizer), waking workers that wait for a
/// core can make two threads several times slower than one. The chooser keeps an exponential
/// average of the time per item of each choice (weight `smoothing` on the newest step), takes
/// the lower one, and makes every `probe_every`-th step with the other choice, whose measured
/// time then replaces that choice's average, to follow a load that changes. The first step of each choice is not counted (it tabulates, allocates and
/// wakes the thread pool).
class ThreadChooser {
 public:
  /// `most`: the threads of "every core" (resolve_threads(0)); 1 makes the choice fixed.
  explicit ThreadChooser(int most, int probe_every = 50, double smoothing = 0.25);

  /// The threads of the next step.
  int threads() const { return next_; }
  /// The step just made with threads() took `seconds` for `items` items (particles).
  void record(double seconds, std::size_t items);
  /// The averaged seconds per item with one thread and with `most` (NaN while not measured).
  double cost_one() const { return cost_[0]; }
  double cost_most() const { return cost_[1]; }

 private:
  int most_, probe_every_;
  double smoothing_;
  double cost_[2];
  bool warmed_[2] = {false, false};
  int next_;
  int since_probe_ = 0;
  bool probing_ = false;  // the next step is a probe of the other choice
};

}  // namespace kiseki
