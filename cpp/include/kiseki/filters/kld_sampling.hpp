// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include "kiseki/core/pose.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/filters/resampling.hpp"

namespace kiseki {

/// KLD sampling (Fox, "Adapting the sample size in particle filters through KLD-sampling",
/// IJRR 22(12), 2003, eq. 14): the number of samples for which, with probability 1 - delta, the
/// K-L divergence between the sample-based and the true posterior stays below err, when the
/// samples fall into k bins:
///   n = (k - 1) / (2 err) (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z)^3,
/// z the upper 1 - delta quantile of the standard normal. As in nav2 AMCL, the parameter is z
/// itself (nav2's pf_z, default 0.99) and err is pf_err (default 0.05). k <= 1 gives 0.
std::size_t kld_sample_bound(std::size_t bins, double err, double z);

/// Parameters of KLD sampling: the bound and the bin sizes of the histogram over the state.
struct KldParams {
  double err = 0.05;  ///< nav2's pf_err
  double z = 0.99;    ///< nav2's pf_z
  double bin_xy = 0.5;                   ///< m (nav2's kd-tree cell: 0.5 m)
  double bin_theta = 0.17453292519943295;  ///< rad (nav2: 10 degrees)
  double bin_distance = 0.1;             ///< m, for the 1-D travel-distance state
  std::size_t min_particles = 500;       ///< nav2's min_particles
  std::size_t max_particles = 2000;      ///< nav2's max_particles
  void validate() const;
};

/// The occupied bins of a growing sample.
class KldBins {
 public:
  /// Checks err and z once here: enough() runs for every particle drawn.
  explicit KldBins(const KldParams& params);
  /// Adds a sample; returns true if it fell into a new bin.
  bool add(const Pose2& pose);
  bool add(double distance);
  std::size_t bins() const { return bins_.size(); }
  /// Whether n samples are enough for the bins seen so far (and n >= min_particles).
  bool enough(std::size_t n) const;

 private:
  KldParams params_;
  std::unordered_set<std::uint64_t> bins_;
};

/// Resampled states: n = params.max_particles indices drawn from the weights by `method`; with
/// KLD sampling they are taken in random order until the bound for the bins filled so far is met
/// (Fox 2003, Table 1, with the draws made up front), else all n. State is Pose2 or double.
/// `binned(state)` gives what KLD bins (the state itself by default; a particle's distance
/// when the states are indices).
template <typename State, typename Binned = State (*)(const State&)>
std::vector<State> resample_states(const std::vector<State>& states, const std::vector<double>& weights,
                                   std::size_t n, ResamplingMethod method, bool kld,
                                   const KldParams& params, Random& rng,
                                   Binned binned = [](const State& s) { return s; }) {
  std::vector<std::size_t> idx = resample_indices(weights, n, method, rng);
  std::vector<State> out;
  out.reserve(n);
  if (!kld) {
    for (std::size_t i : idx) out.push_back(states[i]);
    return out;
  }
  for (std::size_t i = idx.size(); i > 1; --i) std::swap(idx[i - 1], idx[rng.below(i)]);
  KldBins bins(params);
  for (std::size_t i : idx) {
    out.push_back(states[i]);
    bins.add(binned(states[i]));
    if (bins.enough(out.size())) break;
  }
  return out;
}

}  // namespace kiseki
