// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/travel_distance_filter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kiseki/core/parallel.hpp"

namespace kiseki {

void TravelDistanceParams::validate() const {
  if (particles < 1 || particles > 10'000'000) throw std::invalid_argument("travel distance filter: particles must be in 1..10,000,000");
  if (kld) {
    KldParams k = kld_params;
    k.max_particles = particles;
    k.validate();
  }
  if (!(resample_threshold >= 0.0) || !std::isfinite(resample_threshold)) {
    throw std::invalid_argument("travel distance filter: resample_threshold must be >= 0");
  }
  check_likelihood_power(likelihood_power, "travel distance filter");  // the MCL's (0, 1000]
  check_threads(threads, "travel distance filter");
}

TravelDistanceFilter::TravelDistanceFilter(const TravelDistanceParams& params, std::uint64_t seed)
    : params_((params.validate(), params)), rng_(seed) {
  params_.kld_params.max_particles = params_.particles;
}

void TravelDistanceFilter::initialize(double mean, double sd) {
  if (!std::isfinite(mean) || !(sd >= 0.0) || !std::isfinite(sd)) {
    throw std::invalid_argument("travel distance filter: the initial mean and SD must be finite, SD >= 0");
  }
  std::vector<double> p(params_.particles);
  for (double& s : p) s = rng_.normal(mean, sd);
  set_particles(p);
}

void TravelDistanceFilter::set_particles(const std::vector<double>& d, const std::vector<double>& w) {
  if (d.empty()) throw std::invalid_argument("travel distance filter: no particles");
  for (double s : d) {
    if (!std::isfinite(s)) throw std::invalid_argument("travel distance filter: particles must be finite");
  }
  particles_ = d;
  scales_.assign(d.size(), 1.0);
  if (w.empty()) weights_.assign(d.size(), 1.0 / static_cast<double>(d.size()));
  else set_weights(w);
}

void TravelDistanceFilter::set_weights(const std::vector<double>& w) {
  if (w.size() != particles_.size()) throw std::invalid_argument("travel distance filter: one weight per particle is needed");
  double total = 0.0;
  for (double v : w) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw std::invalid_argument("travel distance filter: weights must be finite and >= 0");
    total += v;
  }
  if (!(total > 0.0) || !std::isfinite(total)) throw std::invalid_argument("travel distance filter: the weights sum to 0");
  weights_ = w;
  for (double& v : weights_) v /= total;
}

void TravelDistanceFilter::set_scales(const std::vector<double>& k) {
  if (k.size() != particles_.size()) throw std::invalid_argument("travel distance filter: one scale per particle is needed");
  for (double v : k) {
    if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument("travel distance filter: scales must be finite and > 0");
  }
  scales_ = k;
}

void TravelDistanceFilter::predict_scaled(double distance, double sd, double scale_sd) {
  if (particles_.empty()) throw std::logic_error("travel distance filter: not initialised");
  if (!std::isfinite(distance) || !(sd >= 0.0) || !std::isfinite(sd) || !(scale_sd >= 0.0) || !std::isfinite(scale_sd)) {
    throw std::invalid_argument("travel distance filter: distance and SDs must be finite, SDs >= 0");
  }
  const std::uint64_t seed = rng_.below(~std::uint64_t{0});
  parallel_for(particles_.size(), params_.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      StreamRandom g(seed, i);
      const double k = scales_[i] + g.normal(0.0, scale_sd);
      if (k > 0.0) scales_[i] = k;
      particles_[i] += scales_[i] * distance + g.normal(0.0, sd);
    }
  }, 4096);
}

void TravelDistanceFilter::predict(double distance, double sd) {
  if (particles_.empty()) throw std::logic_error("travel distance filter: not initialised");
  if (!std::isfinite(distance) || !(sd >= 0.0) || !std::isfinite(sd)) {
    throw std::invalid_argument("travel distance filter: distance and SD must be finite, SD >= 0");
  }
  const std::uint64_t seed = rng_.below(~std::uint64_t{0});
  parallel_for(particles_.size(), params_.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      StreamRandom g(seed, i);
      particles_[i] += distance + g.normal(0.0, sd);
    }
  }, 4096);
}

bool TravelDistanceFilter::update(const std::vector<double>& log_l) {
  if (particles_.empty()) throw std::logic_error("travel distance filter: not initialised");
  const bool changed = apply_log_likelihoods(weights_, log_l, params_.likelihood_power);
  const double n = static_cast<double>(particles_.size());
  if (params_.resample_threshold >= 1.0 || effective_sample_size() < params_.resample_threshold * n) {
    // the particles' indices as the states, so that each scale follows its distance (the KLD
    // bins are those of the distances: the index's particle is binned)
    std::vector<std::size_t> index(particles_.size());
    for (std::size_t i = 0; i < index.size(); ++i) index[i] = i;
    const std::vector<std::size_t> picked = resample_states(index, weights_, params_.particles, params_.resampling,
                                                            params_.kld, params_.kld_params, rng_,
                                                            [this](std::size_t i) { return particles_[i]; });
    std::vector<double> d(picked.size()), k(picked.size());
    for (std::size_t j = 0; j < picked.size(); ++j) {
      d[j] = particles_[picked[j]];
      k[j] = scales_[picked[j]];
    }
    particles_.swap(d);
    scales_.swap(k);
    weights_.assign(particles_.size(), 1.0 / static_cast<double>(particles_.size()));
  }
  return changed;
}

double TravelDistanceFilter::estimate() const {
  if (particles_.empty()) throw std::logic_error("travel distance filter: not initialised");
  double m = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) m += weights_[i] * particles_[i];
  return m;
}

double TravelDistanceFilter::variance() const {
  const double m = estimate();
  double v = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) v += weights_[i] * (particles_[i] - m) * (particles_[i] - m);
  return v;
}

double TravelDistanceFilter::effective_sample_size() const { return kiseki::effective_sample_size(weights_); }

}  // namespace kiseki
