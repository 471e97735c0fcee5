// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <array>
#include <cstddef>

namespace kiseki {

/// Chooses, step by step, between one thread and every core for loops whose results do not
/// depend on the thread count (the choice changes the time only), from the measured time of
/// the steps made with each. On a free machine every core is faster; on one whose cores other
/// processes keep busy (a robot's planner, a second localizer), waking workers that wait for a
/// core can make two threads several times slower than one.
///
/// Each choice keeps its last kKept times per item; its cost is their median (a step that the
/// scheduler preempts does not move it). The first steps alternate the two choices until each
/// has kFirst measured steps after one not counted (the first step of a choice allocates and
/// wakes the thread pool); then the cheaper is taken, and the other is made once every
/// probe_every x (its cost / the cheaper's) steps, so that a load that changes is followed and
/// a choice much slower than the other is tried seldom (the probes cost about 1 / probe_every
/// of a step's time whatever the ratio).
class ThreadChooser {
 public:
  static constexpr int kKept = 5;
  static constexpr int kFirst = 3;

  /// `most`: the threads of "every core" (resolve_threads(0)); 1 makes the choice fixed.
  explicit ThreadChooser(int most, int probe_every = 50);

  /// The threads of the next step.
  int threads() const { return next_; }
  /// The step just made with threads() took `seconds` for `items` items (particles).
  void record(double seconds, std::size_t items);
  /// The median seconds per item of one thread and of `most` (NaN while not measured).
  double cost_one() const { return cost(0); }
  double cost_most() const { return cost(1); }

 private:
  double cost(int k) const;

  int most_, probe_every_;
  std::array<std::array<double, kKept>, 2> kept_{};  // ring buffers, one thread and `most`
  std::array<int, 2> count_{0, 0};                    // measured steps of each (all time)
  std::array<bool, 2> warmed_{false, false};
  int next_;
  int since_probe_ = 0;
};

}  // namespace kiseki
