// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/monte_carlo_localization.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"

namespace kiseki {

Recovery recovery_from_name(const std::string& name) {
  if (name == "none") return Recovery::none;
  if (name == "augmented") return Recovery::augmented;
  if (name == "resetting") return Recovery::resetting;
  throw std::invalid_argument("recovery: unknown '" + name + "' (none, augmented or resetting)");
}

void MclParams::validate() const {
  if (particles < 1 || particles > 10'000'000) throw std::invalid_argument("MCL: particles must be in 1..10,000,000");
  // KLD's err, z and bins are checked with kld off too (a NaN err was held unused); the counts
  // only with it on
  KldParams k = kld_params;
  k.max_particles = particles;
  if (!kld) k.min_particles = 1;
  if (k.min_particles > particles) throw std::invalid_argument("MCL: KLD min_particles exceeds particles (the maximum)");
  k.validate();
  motion.validate();
  // a share of n (1: every update); above it the same as 1
  if (!(resample_threshold >= 0.0 && resample_threshold <= 1.0)) {
    throw std::invalid_argument("MCL: resample_threshold must lie in [0, 1]");
  }
  check_likelihood_power(likelihood_power, "MCL");  // (0, 1000]: a scan counted as up to 1,000
  if (!(alpha_slow > 0.0 && alpha_slow <= 1.0 && alpha_fast > 0.0 && alpha_fast <= 1.0)) {
    throw std::invalid_argument("MCL: alpha_slow and alpha_fast must lie in (0, 1]");
  }
  if (!(reset_threshold >= 0.0 && reset_threshold <= 1.0)) throw std::invalid_argument("MCL: reset_threshold must lie in [0, 1]");
  // nats: more than a scan of 100,000 beams (kiseki's most, a few nats each) shows: no reset passes
  if (!(reset_evidence >= 0.0 && reset_evidence <= 1e6)) throw std::invalid_argument("MCL: reset_evidence must lie in [0, 1e6]");
  if (!(reset_likelihood_drop >= 0.0 && reset_likelihood_drop < 1.0)) {
    throw std::invalid_argument("MCL: reset_likelihood_drop must lie in [0, 1)");
  }
  // wider than the robot may move between two updates, or a half turn: a global reset (the sensor reset's)
  if (!(expansion_position >= 0.0 && expansion_position <= kMaxOdometryJump) ||
      !(expansion_orientation >= 0.0 && expansion_orientation <= kPi)) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", kMaxOdometryJump);
    throw std::invalid_argument(std::string("MCL: expansion radii must lie in [0, ") + limit + " m] and [0, pi]");
  }
  if (reset_after < 1 || sensor_reset_after < reset_after || sensor_reset_after > 1'000'000) {
    throw std::invalid_argument("MCL: need 1 <= reset_after <= sensor_reset_after <= 1,000,000 updates");
  }
  if (!(sensor_reset_share >= 0.0 && sensor_reset_share <= 1.0)) throw std::invalid_argument("MCL: sensor_reset_share must lie in [0, 1]");
  if (sensor_reset_candidates < 1 || sensor_reset_candidates > 10'000'000) {
    throw std::invalid_argument("MCL: sensor_reset_candidates must be in 1..10,000,000");
  }
  if (matcher_search_every < 1 || matcher_search_every > 1000) {
    throw std::invalid_argument("MCL: matcher_search_every must be in 1..1000");
  }
  if (!(reliability_rate > 0.0 && reliability_rate <= 1.0)) throw std::invalid_argument("MCL: reliability_rate must lie in (0, 1]");
  check_threads(threads, "MCL");
}

MonteCarloLocalization::MonteCarloLocalization(const MclParams& params, std::uint64_t seed)
    : params_((params.validate(), params)),
      rng_(seed),
      target_(params.particles),
      chooser_(params.threads > 0 ? params.threads : resolve_threads(0)) {
  params_.kld_params.max_particles = params_.particles;
}

void MonteCarloLocalization::set_free_space(const OccupancyGrid& map) {
  std::vector<std::int32_t> cells;
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      if (is_free(map.value(x, y))) cells.push_back(y * map.width() + x);
    }
  }
  if (cells.empty()) throw std::invalid_argument("MCL: the map has no free cell to draw poses from");
  free_cells_ = std::move(cells);
  free_width_ = map.width();
  free_resolution_ = map.resolution();
  free_origin_ = map.origin();
}

std::vector<Pose2> MonteCarloLocalization::uniform_poses(std::size_t n) {
  if (free_cells_.empty()) throw std::logic_error("MCL: no free space set (set_free_space)");
  std::vector<Pose2> out(n);
  for (auto& p : out) {
    const std::int32_t cell = free_cells_[rng_.below(free_cells_.size())];
    const double gx = cell % free_width_ + rng_.uniform(), gy = cell / free_width_ + rng_.uniform();
    const Eigen::Vector2d w = free_origin_.transform_point({gx * free_resolution_, gy * free_resolution_});
    p = Pose2(w.x(), w.y(), rng_.uniform(-kPi, kPi));
  }
  return out;
}

void MonteCarloLocalization::initialize_gaussian(const Pose2& mean, double sd_x, double sd_y, double sd_theta) {
  if (!(sd_x >= 0.0) || !(sd_y >= 0.0) || !(sd_theta >= 0.0) || !std::isfinite(sd_x + sd_y + sd_theta)) {
    throw std::invalid_argument("MCL: standard deviations must be finite and >= 0");
  }
  if (!std::isfinite(mean.x) || !std::isfinite(mean.y) || !std::isfinite(mean.theta)) {
    throw std::invalid_argument("MCL: the initial pose must be finite");
  }
  std::vector<Pose2> p(params_.particles);
  for (auto& q : p) q = Pose2(rng_.normal(mean.x, sd_x), rng_.normal(mean.y, sd_y), rng_.normal(mean.theta, sd_theta));
  set_particles(p);
  posterior_ = estimate();
  reliability_ = 1.0;
}

void MonteCarloLocalization::initialize_uniform() {
  set_particles(uniform_poses(params_.particles));
  posterior_ = estimate();
  reliability_ = 0.0;
}

void MonteCarloLocalization::set_particles(const std::vector<Pose2>& poses, const std::vector<double>& weights) {
  if (poses.empty()) throw std::invalid_argument("MCL: no particles");
  if (poses.size() > 10'000'000) throw std::invalid_argument("MCL: more than 10,000,000 particles");
  for (const auto& q : poses) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.theta)) {
      throw std::invalid_argument("MCL: particles must be finite");
    }
  }
  if (!weights.empty() && weights.size() != poses.size()) {
    throw std::invalid_argument("MCL: one weight per particle is needed");
  }
  particles_ = poses;
  challenger_.clear();  // a new cloud: a sensor reset held for the old one is void
  predicted_seconds_ = 0.0;  // and a motion update of the old one is not its step's
  matcher_found_.clear();
  if (weights.empty()) {
    weights_.assign(particles_.size(), 1.0 / static_cast<double>(particles_.size()));
  } else {
    set_weights(weights);
  }
}

void MonteCarloLocalization::set_weights(const std::vector<double>& weights) {
  if (weights.size() != particles_.size()) throw std::invalid_argument("MCL: one weight per particle is needed");
  double total = 0.0;
  for (double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) throw std::invalid_argument("MCL: weights must be finite and >= 0");
    total += w;
  }
  if (!(total > 0.0) || !std::isfinite(total)) throw std::invalid_argument("MCL: the weights sum to 0");
  weights_.resize(weights.size());
  for (std::size_t i = 0; i < weights.size(); ++i) weights_[i] = weights[i] / total;
}

void MonteCarloLocalization::check_ready() const {
  if (particles_.empty()) throw std::logic_error("MCL: not initialised (no particles)");
}

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }
}  // namespace

void MonteCarloLocalization::predict(const Pose2& a, const Pose2& b) {
  check_ready();
  const double step = std::hypot(b.x - a.x, b.y - a.y);
  if (std::isfinite(a.x) && std::isfinite(b.x) && step > kMaxOdometryJump) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "MCL: odometry jumps %.4g m between two updates: more than kiseki's limit of %g m", step,
                  kMaxOdometryJump);
    throw std::invalid_argument(text);
  }
  const auto start = Clock::now();
  const std::uint64_t step_seed = rng_.below(~std::uint64_t{0});
  sample_motion(params_.motion, a, b, particles_.data(), particles_.size(), step_seed, threads_now());
  if (!challenger_.empty()) {
    sample_motion(params_.motion, a, b, challenger_.data(), challenger_.size(), rng_.below(~std::uint64_t{0}),
                  threads_now());
  }
  // the cloud's share of the time (a held sensor reset's particles moved too), as the chooser
  // counts the time per particle weighed
  const auto moved = static_cast<double>(particles_.size() + challenger_.size());
  predicted_seconds_ += seconds_since(start) * static_cast<double>(particles_.size()) / moved;
  const Pose2 step_taken = a.between(b);  // places, not particles: moved without noise
  for (PoseHypothesis& h : matcher_found_) h.pose = h.pose.compose(step_taken);
}

std::vector<double> MonteCarloLocalization::evaluate(const SensorModel& model, const std::vector<Pose2>& poses) const {
  std::vector<double> out(poses.size());
  parallel_for(poses.size(), threads_now(),
               [&](std::size_t b, std::size_t e) { model.log_likelihoods(poses.data() + b, e - b, out.data() + b); }, 64);
  return out;
}

double MonteCarloLocalization::agreement_of(const SensorModel& model, const Pose2& weighed) const {
  // At the filter's answer, the weighted mean after weighing: a single particle of a tracking
  // cloud is further off than the mean, and long beams turn its heading error into metres.
  return model.agreement(weighed);
}

UpdateReport MonteCarloLocalization::update(SensorModel& model) { return weigh(&model, model, nullptr); }

UpdateReport MonteCarloLocalization::update(const SensorModel& model) { return weigh(nullptr, model, nullptr); }

UpdateReport MonteCarloLocalization::update(SensorModel& model, const ScanView& scan) {
  return weigh(&model, model, &scan);
}

UpdateReport MonteCarloLocalization::update(const SensorModel& model, const ScanView& scan) {
  return weigh(nullptr, model, &scan);
}

UpdateReport MonteCarloLocalization::weigh(SensorModel* selects, const SensorModel& model, const ScanView* scan) {
  check_ready();
  const bool matcher = params_.recovery == Recovery::resetting && params_.sensor_reset_proposal == ResetProposal::matcher;
  if (scan == nullptr && matcher) throw std::logic_error("MCL: the matcher proposal needs the scan: update(model, scan)");
  if (scan != nullptr && scan->n > 0 && (scan->angles == nullptr || scan->ranges == nullptr)) {
    throw std::invalid_argument("MCL: a scan without beams");
  }
  if (scan != nullptr && matcher && matcher_ == nullptr) {
    throw std::logic_error("MCL: the matcher proposal needs a correlative scan matcher (set_matcher)");
  }
  const auto start = Clock::now();
  const std::size_t weighed = particles_.size();  // before resampling changes the count (KLD)
  if (selects != nullptr) selects->select_readings(particles_.data(), particles_.size(), threads_now());
  const std::vector<double> log_l = evaluate(model, particles_);
  UpdateReport report =
      update_impl(log_l, model.readings(), std::numeric_limits<double>::quiet_NaN(), &model, scan);
  record_step(seconds_since(start), weighed);
  return report;
}

UpdateReport MonteCarloLocalization::update(const std::vector<double>& log_l, std::size_t readings, double agreement) {
  check_ready();
  if (!std::isnan(agreement) && !(agreement >= 0.0 && agreement <= 1.0)) {
    throw std::invalid_argument("MCL: agreement must lie in [0, 1] (or be NaN)");
  }
  const auto start = Clock::now();
  const std::size_t weighed = particles_.size();
  UpdateReport report = update_impl(log_l, readings, agreement, nullptr, nullptr);
  record_step(seconds_since(start), weighed);
  return report;
}

void MonteCarloLocalization::record_step(double update_seconds, std::size_t weighed) {
  // The whole step, the motion update's share included: against busy cores two threads can
  // weigh as fast as one while their motion update takes ten times one thread's (10,000
  // particles), and timing the weighing alone chose the slower step.
  chooser_.record(predicted_seconds_ + update_seconds, weighed);
  predicted_seconds_ = 0.0;
}

UpdateReport MonteCarloLocalization::update_impl(const std::vector<double>& log_l, std::size_t readings,
                                                 double agreement, const SensorModel* model,
                                                 const ScanView* scan) {
  if (log_l.size() != particles_.size()) throw std::invalid_argument("MCL: one log-likelihood per particle is needed");
  UpdateReport report;
  searched_ = false;
  // Augmented MCL's average likelihood: the weighted mean of the per-reading (geometric mean)
  // likelihood, so that scans with more or fewer returns compare.
  const double r = static_cast<double>(std::max<std::size_t>(readings, 1));
  double top = -std::numeric_limits<double>::infinity();
  for (double l : log_l) {
    if (std::isnan(l)) throw std::invalid_argument("MCL: a log-likelihood is NaN");
    top = std::max(top, l / r);
  }
  double w_avg = 0.0;
  if (std::isfinite(top)) {
    // The terms on the threads, their sum in particle order: the same for any thread count.
    std::vector<double> terms(log_l.size());
    parallel_for(terms.size(), threads_now(), [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) terms[i] = weights_[i] * std::exp(log_l[i] / r - top);
    }, kParallelExps);
    for (double t : terms) w_avg += t;
    w_avg *= std::exp(top);
  }
  report.average_likelihood = w_avg;
  report.informative =
      readings > 0 && apply_log_likelihoods(weights_, log_l, params_.likelihood_power, threads_now());
  report.effective_sample_size = kiseki::effective_sample_size(weights_);
  if (report.informative && std::isfinite(w_avg)) {
    if (w_slow_ == 0.0) w_slow_ = w_fast_ = w_avg;
    w_slow_ += params_.alpha_slow * (w_avg - w_slow_);
    w_fast_ += params_.alpha_fast * (w_avg - w_fast_);
  }
  const double ratio = w_slow_ > 0.0 ? w_fast_ / w_slow_ : 1.0;
  // The weighted mean after weighing: where the agreement is taken and, unless a reset moves
  // the particles, the posterior (computed once for both).
  const Pose2 weighed = estimate();
  if (model != nullptr) agreement = agreement_of(*model, weighed);
  report.agreement = agreement;
  const bool knows = !std::isnan(agreement);
  // Where the model cannot tell, the likelihood's drop decides alone (off with a drop of 0).
  const bool lost = knows ? agreement < params_.reset_threshold : ratio < params_.reset_likelihood_drop;
  const double signal = knows ? (lost ? 0.0 : 1.0) : std::min(1.0, ratio);
  reliability_ += params_.reliability_rate * (signal - reliability_);
  // emcl2's second trigger: the likelihood has dropped against its long-term average. It sees
  // a cloud carried to a place that looks alike, whose scans still mostly agree with the map.
  const bool dropped = ratio < params_.reset_likelihood_drop;

  if (params_.recovery == Recovery::resetting && (lost || dropped || !report.informative)) ++lost_updates_;
  // Reset only when the disagreement persists (reset_after updates in a row): one scan through
  // a glass door or into an unmapped room must not scatter a cloud that is right.
  if (params_.recovery == Recovery::resetting && lost_updates_ >= params_.reset_after) {
    double best = -std::numeric_limits<double>::infinity();
    for (double l : log_l) best = std::max(best, l);
    // The cloud's place in the terms a proposed place is judged by, at agreement_of's pose.
    const CloudScore cloud{best, model != nullptr ? model->placement_agreement(weighed) : agreement};
    bool sensed = false;
    if (model != nullptr && !challenger_.empty()) sensed = confirm_challenger(*model, cloud);
    if (!sensed && model != nullptr && has_free_space() && lost_updates_ >= params_.sensor_reset_after) {
      sensed = sensor_reset(*model, cloud, scan);
    }
    if (sensed) end_lost_spell();
    const bool expanded = !sensed && expansion_reset(model, cloud);
    report.searched = searched_;
    if (sensed || expanded) {
      report.reset = sensed ? "sensor" : "expansion";
      posterior_ = estimate();
      report.resampled = true;
      report.particles = particles_.size();
      return report;
    }
  }
  if (!lost && !dropped) {
    end_lost_spell();  // the cloud agrees again
  }
  posterior_ = weighed;  // before resampling: injected poses have no weight in it
  double inject = 0.0;
  const bool injects = params_.recovery == Recovery::augmented ||
                       (params_.recovery == Recovery::resetting && params_.resetting_injects);
  if (injects && has_free_space()) inject = std::max(0.0, 1.0 - ratio);
  if (inject > 0.0 || params_.resample_threshold >= 1.0 ||
      report.effective_sample_size < params_.resample_threshold * static_cast<double>(particles_.size())) {
    resample(inject, report);
  }
  report.particles = particles_.size();
  return report;
}

void MonteCarloLocalization::resample(double inject, UpdateReport& report) {
  const std::size_t n = params_.kld ? params_.particles : target_;
  std::vector<Pose2> out;
  if (params_.kld) {
    out = resample_states(particles_, weights_, n, params_.resampling, true, params_.kld_params, rng_);
  } else {  // resample_states without KLD, with the logarithms of the draws on the threads
    const std::vector<std::size_t> idx = resample_indices(weights_, n, params_.resampling, rng_, threads_now());
    out.resize(idx.size());
    for (std::size_t i = 0; i < idx.size(); ++i) out[i] = particles_[idx[i]];
  }
  if (inject > 0.0) {
    std::size_t m = 0;
    for (std::size_t i = 0; i < out.size(); ++i) m += rng_.uniform() < inject;
    const std::vector<Pose2> fresh = uniform_poses(m);
    for (std::size_t i = 0; i < m; ++i) out[out.size() - 1 - i] = fresh[i];
    report.injected = m;
  }
  particles_.swap(out);
  weights_.assign(particles_.size(), 1.0 / static_cast<double>(particles_.size()));
  report.resampled = true;
}

void MonteCarloLocalization::set_likelihood_power(double power) {
  MclParams p = params_;
  p.likelihood_power = power;
  p.validate();
  params_ = p;
}

void MonteCarloLocalization::set_recovery(Recovery recovery) {
  params_.recovery = recovery;
  w_slow_ = w_fast_ = 0.0;  // the averages start again from the next update
  end_lost_spell();
}

void MonteCarloLocalization::end_lost_spell() {
  lost_updates_ = 0;
  challenger_.clear();     // nothing held to confirm
  matcher_found_.clear();  // the next spell searches anew
}

void MonteCarloLocalization::resample_to(std::size_t n) {
  check_ready();
  if (n < 1 || n > 10'000'000) throw std::invalid_argument("MCL: resample_to needs 1..10,000,000 particles");
  const std::vector<std::size_t> idx = resample_indices(weights_, n, params_.resampling, rng_);
  std::vector<Pose2> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = particles_[idx[i]];
  particles_.swap(out);
  weights_.assign(n, 1.0 / static_cast<double>(n));
  target_ = n;
}

}  // namespace kiseki
