// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/resampling.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "kiseki/core/parallel.hpp"

namespace kiseki {

ResamplingMethod resampling_method_from_name(const std::string& name) {
  if (name == "multinomial") return ResamplingMethod::multinomial;
  if (name == "systematic") return ResamplingMethod::systematic;
  if (name == "stratified") return ResamplingMethod::stratified;
  if (name == "residual") return ResamplingMethod::residual;
  throw std::invalid_argument("resampling: unknown method '" + name +
                              "' (multinomial, systematic, stratified or residual)");
}

const char* resampling_method_name(ResamplingMethod method) {
  switch (method) {
    case ResamplingMethod::multinomial: return "multinomial";
    case ResamplingMethod::systematic: return "systematic";
    case ResamplingMethod::stratified: return "stratified";
    case ResamplingMethod::residual: return "residual";
  }
  return "?";
}

namespace {

std::vector<double> cumulative(const std::vector<double>& w) {
  std::vector<double> c(w.size());
  double total = 0.0;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (!(w[i] >= 0.0) || !std::isfinite(w[i])) throw std::invalid_argument("resampling: weights must be finite and >= 0");
    total += w[i];
    c[i] = total;
  }
  if (!(total > 0.0)) throw std::invalid_argument("resampling: the weights sum to 0");
  for (double& v : c) v /= total;
  c.back() = 1.0;
  return c;
}

// Indices for sorted pointers u_0 <= ... <= u_{n-1} in [0, 1).
void walk(const std::vector<double>& cum, const std::vector<double>& u, std::vector<std::size_t>& out) {
  std::size_t i = 0;
  for (double v : u) {
    while (v >= cum[i] && i + 1 < cum.size()) ++i;
    out.push_back(i);
  }
}

}  // namespace

std::vector<std::size_t> resample_indices(const std::vector<double>& weights, std::size_t n,
                                          ResamplingMethod method, Random& rng, int threads) {
  if (weights.empty()) throw std::invalid_argument("resampling: no particles");
  const std::vector<double> cum = cumulative(weights);
  std::vector<std::size_t> out;
  out.reserve(n);
  if (n == 0) return out;
  std::vector<double> u(n);
  switch (method) {
    case ResamplingMethod::multinomial: {
      // Sorted uniforms from normalised exponential spacings, so one pass suffices. The draws
      // in order, their logs on the threads, the running sum in order: the same for any count.
      std::vector<double> e(n + 1);
      for (double& v : e) v = rng.uniform();
      parallel_for(e.size(), threads, [&](std::size_t b, std::size_t end) {
        for (std::size_t m = b; m < end; ++m) e[m] = -std::log(1.0 - e[m]);
      }, kParallelExps);
      double acc = 0.0;
      for (std::size_t m = 0; m <= n; ++m) {
        acc += e[m];
        if (m < n) u[m] = acc;
      }
      for (double& v : u) v /= acc;
      walk(cum, u, out);
      break;
    }
    case ResamplingMethod::systematic: {
      const double u0 = rng.uniform();
      for (std::size_t m = 0; m < n; ++m) u[m] = (static_cast<double>(m) + u0) / static_cast<double>(n);
      walk(cum, u, out);
      break;
    }
    case ResamplingMethod::stratified: {
      for (std::size_t m = 0; m < n; ++m) u[m] = (static_cast<double>(m) + rng.uniform()) / static_cast<double>(n);
      walk(cum, u, out);
      break;
    }
    case ResamplingMethod::residual: {
      std::vector<double> residue(weights.size());
      double prev = 0.0;
      std::size_t copied = 0;
      for (std::size_t i = 0; i < weights.size(); ++i) {
        const double expected = (cum[i] - prev) * static_cast<double>(n);
        prev = cum[i];
        const auto copies = static_cast<std::size_t>(std::floor(expected));
        for (std::size_t c = 0; c < copies && copied < n; ++c, ++copied) out.push_back(i);
        residue[i] = std::max(0.0, expected - static_cast<double>(copies));
      }
      const std::size_t rest = n - copied;
      if (rest > 0) {
        const double sum = std::accumulate(residue.begin(), residue.end(), 0.0);
        // All residues 0 happens only through rounding: fall back to the weights themselves.
        const auto extra = resample_indices(sum > 0.0 ? residue : weights, rest, ResamplingMethod::multinomial, rng);
        out.insert(out.end(), extra.begin(), extra.end());
      }
      break;
    }
  }
  return out;
}

double effective_sample_size(const std::vector<double>& weights) {
  double s = 0.0;
  for (double w : weights) s += w * w;
  return s > 0.0 ? 1.0 / s : 0.0;
}

void check_likelihood_power(double power, const char* who) {
  if (!(power > 0.0 && power <= kMaxLikelihoodPower)) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", kMaxLikelihoodPower);
    throw std::invalid_argument(std::string(who) + ": likelihood_power must lie in (0, " + limit + "]");
  }
}

bool apply_log_likelihoods(std::vector<double>& weights, const std::vector<double>& log_l, double power,
                           int threads) {
  if (log_l.size() != weights.size()) throw std::invalid_argument("weights: one log-likelihood per particle is needed");
  if (!(power > 0.0) || !std::isfinite(power)) throw std::invalid_argument("weights: the likelihood power must be > 0");
  // log w_i + power log l_i for every particle; after a resampling every weight is the same,
  // so the log of a weight equal to the one before is that one's (the same value, once).
  std::vector<double> w(weights.size());
  double top = -std::numeric_limits<double>::infinity();
  double last_weight = std::numeric_limits<double>::quiet_NaN(), last_log = 0.0;
  for (std::size_t i = 0; i < log_l.size(); ++i) {
    if (std::isnan(log_l[i]) || log_l[i] == std::numeric_limits<double>::infinity()) {
      throw std::invalid_argument("weights: a log-likelihood is NaN or +inf");
    }
    if (weights[i] > 0.0) {
      if (weights[i] != last_weight) last_weight = weights[i], last_log = std::log(weights[i]);
      w[i] = power * log_l[i] + last_log;
      top = std::max(top, w[i]);
    }
  }
  if (!std::isfinite(top)) return false;
  parallel_for(w.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) w[i] = weights[i] > 0.0 ? std::exp(w[i] - top) : 0.0;
  }, kParallelExps);
  double total = 0.0;
  for (double v : w) total += v;  // in particle order, for any thread count
  if (!(total > 0.0) || !std::isfinite(total)) return false;
  for (std::size_t i = 0; i < w.size(); ++i) weights[i] = w[i] / total;
  return true;
}

}  // namespace kiseki
