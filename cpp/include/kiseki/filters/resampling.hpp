// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "kiseki/core/random.hpp"

namespace kiseki {

/// Resampling schemes (Douc, Cappe and Moulines, "Comparison of resampling schemes for particle
/// filtering", ISPA 2005), for any particle state: they pick indices from the weights.
enum class ResamplingMethod {
  multinomial,  ///< n independent draws from the weights
  systematic,   ///< one uniform offset, n evenly spaced pointers (low variance, PR Table 4.4)
  stratified,   ///< one uniform draw in each of n equal strata
  residual,     ///< floor(n w_i) copies of each, the remainder multinomial on the residues
};
ResamplingMethod resampling_method_from_name(const std::string& name);
const char* resampling_method_name(ResamplingMethod method);

/// The fewest particles a thread takes in the engine's loops of a few arithmetic operations and
/// an exponential or a sine per particle (weights, the weighted mean): about 100 us of work,
/// well over what waking a sleeping OpenMP worker costs.
inline constexpr std::size_t kParallelExps = 8192;

/// n indices into weights (normalised or not, all finite and >= 0, positive sum), drawn by method.
/// `threads`: multinomial's logarithms are taken on up to that many threads (the draws and the
/// sums stay in order on the calling one: the same indices for any count).
std::vector<std::size_t> resample_indices(const std::vector<double>& weights, std::size_t n,
                                          ResamplingMethod method, Random& rng, int threads = 1);

/// Effective sample size 1 / sum w_i^2 of normalised weights (Liu 1996).
double effective_sample_size(const std::vector<double>& weights);

/// The largest likelihood power a filter takes (the MCL engine's and the travel-distance
/// filter's): a measurement counted as up to 1,000 of them; 1e300 overflowed the
/// log-likelihoods to NaN weights.
inline constexpr double kMaxLikelihoodPower = 1000.0;

/// Throws std::invalid_argument naming `who` unless 0 < power <= kMaxLikelihoodPower.
void check_likelihood_power(double power, const char* who);

/// Multiplies weights by exp(power * log_likelihoods) and normalises, in a way that does not
/// underflow (the largest term is taken out). -inf log-likelihoods give weight 0; NaN throws.
/// Returns false and leaves the weights unchanged when no particle has a finite
/// log-likelihood or every product underflows (the measurement carries no usable information).
/// The exponentials are taken on up to `threads` threads and summed in particle order on the
/// calling one, so the weights are the same for any thread count.
bool apply_log_likelihoods(std::vector<double>& weights, const std::vector<double>& log_likelihoods,
                           double power, int threads = 1);

}  // namespace kiseki
