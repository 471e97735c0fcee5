// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The resets of MonteCarloLocalization's resetting recovery: expansion resetting (Ueda et al.,
// emcl) and sensor resetting (Lenser and Veloso, 2000), with their acceptance test.
#include <algorithm>
#include <cmath>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/filters/monte_carlo_localization.hpp"

namespace kiseki {

bool MonteCarloLocalization::explains_better(double proposed_best, double cloud_best) const {
  // The best of many proposed poses beats the cloud's best by chance where the likelihood is
  // flat (a scan of open space): the proposal must be better by a likelihood ratio of
  // exp(reset_evidence), on the scale the weights use.
  return params_.likelihood_power * (proposed_best - cloud_best) > params_.reset_evidence;
}

namespace {

// The place a set of weighed poses proposes: the likelihood-weighted mean of the poses within
// kModeRadius m and kModeHeading rad of the best one (the mode the best one tops). The best of
// many coarse candidates alone is centimetres and degrees off, where the map's agreement with
// a scan falls off sharply (a 0.03 rad heading error takes a true pose's 1.0 to 0.75 in the
// sensor reset test's room); the mean of its mode is nearer, and it never averages two places.
constexpr double kModeRadius = 0.5, kModeHeading = 0.3;

Pose2 proposed_place(const std::vector<Pose2>& poses, const std::vector<double>& log_l) {
  const auto best = static_cast<std::size_t>(std::max_element(log_l.begin(), log_l.end()) - log_l.begin());
  const Pose2& b = poses[best];
  double x = 0, y = 0, c = 0, s = 0, total = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose2& q = poses[i];
    if (std::hypot(q.x - b.x, q.y - b.y) > kModeRadius || std::abs(angle_difference(q.theta, b.theta)) > kModeHeading) {
      continue;
    }
    const double w = std::exp(log_l[i] - log_l[best]);  // the best one's is 1
    x += w * q.x, y += w * q.y, c += w * std::cos(q.theta), s += w * std::sin(q.theta), total += w;
  }
  return {x / total, y / total, std::atan2(s, c)};
}

}  // namespace

bool MonteCarloLocalization::agrees_at(const SensorModel& model, const std::vector<Pose2>& poses,
                                        const std::vector<double>& log_l, const CloudScore& cloud) const {
  if (!params_.reset_needs_agreement) return true;
  const double a = model.placement_agreement(proposed_place(poses, log_l));
  if (std::isnan(a)) return true;  // the model cannot tell
  return a >= params_.reset_threshold &&
         (std::isnan(cloud.placement_agreement) || a >= cloud.placement_agreement);
}

bool MonteCarloLocalization::expansion_reset(const SensorModel* model, const CloudScore& cloud) {
  const std::size_t n = particles_.size();
  const std::vector<std::size_t> idx = resample_indices(weights_, n, params_.resampling, rng_);
  std::vector<Pose2> out(n);
  const std::uint64_t seed = rng_.below(~std::uint64_t{0});
  const double rp = params_.expansion_position, ro = params_.expansion_orientation;
  parallel_for(n, threads_now(), [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      StreamRandom g(seed, i);
      const Pose2& q = particles_[idx[i]];
      const double dx = g.uniform(-rp, rp), dy = g.uniform(-rp, rp), dt = g.uniform(-ro, ro);
      out[i] = Pose2(q.x + dx, q.y + dy, q.theta + dt);
    }
  }, 4096);
  if (model == nullptr) {  // log-likelihoods from elsewhere: cannot weigh again, so keep it
    particles_.swap(out);
    weights_.assign(n, 1.0 / static_cast<double>(n));
    return true;
  }
  // Kept only if some expanded particle explains the measurement better than the best particle
  // did: a cloud that is right but sees an odd scan is not scattered.
  const std::vector<double> l = evaluate(*model, out);
  if (!explains_better(*std::max_element(l.begin(), l.end()), cloud.best_log_likelihood) ||
      !agrees_at(*model, out, l, cloud)) {
    return false;
  }
  particles_.swap(out);
  weights_.assign(n, 1.0 / static_cast<double>(n));
  apply_log_likelihoods(weights_, l, params_.likelihood_power);
  return true;
}

std::vector<Pose2> MonteCarloLocalization::reset_candidates(const ScanView* scan, double& searched) {
  const std::size_t count = params_.sensor_reset_candidates;
  if (params_.sensor_reset_proposal == ResetProposal::uniform) {
    searched = static_cast<double>(count);
    return uniform_poses(count);
  }
  // The matcher's k best distinct lattice poses; the candidates spread around them by one
  // lattice step (a cell per axis, a heading step), as the one-scan start's cloud is. The
  // search is made anew on every matcher_search_every-th reset of a lost spell (predict moves
  // the hypotheses between).
  if (matcher_found_.empty() || matcher_uses_ >= params_.matcher_search_every) {
    matcher_found_ = matcher_->match(scan->angles, scan->ranges, scan->n);
    matcher_headings_ = matcher_->headings(scan->angles, scan->ranges, scan->n);
    matcher_uses_ = 0;
    searched_ = true;
    if (matcher_found_.empty()) return {};  // no beam returned: nothing proposes a place
  }
  ++matcher_uses_;
  searched = static_cast<double>(matcher_->lattice_cells()) * matcher_headings_;
  return poses_around_hypotheses(matcher_found_, count, matcher_->resolution(), 2.0 * kPi / matcher_headings_,
                                 params_.likelihood_power, rng_);
}

std::size_t MonteCarloLocalization::drawn_from_sensor() const {
  return static_cast<std::size_t>(std::llround(params_.sensor_reset_share * static_cast<double>(particles_.size())));
}

bool MonteCarloLocalization::sensor_reset(const SensorModel& model, const CloudScore& cloud, const ScanView* scan) {
  double searched = 1.0;
  const std::vector<Pose2> candidates = reset_candidates(scan, searched);
  if (candidates.empty()) return false;
  const std::vector<double> cand_l = evaluate(model, candidates);
  // The measurement proposes another place only if some pose there explains it better than
  // the best particle of the cloud does; with the look-elsewhere term, by a margin that grows
  // with the number of poses the best was taken from.
  const double penalty = params_.reset_look_elsewhere ? look_elsewhere_term(searched) : 0.0;
  if (!explains_better(*std::max_element(cand_l.begin(), cand_l.end()) - penalty / params_.likelihood_power,
                       cloud.best_log_likelihood) ||
      !agrees_at(model, candidates, cand_l, cloud)) {
    return false;
  }
  if (params_.sensor_reset_confirm) {
    // Held, not made: the poses the reset would draw, confirmed (or not) on the next update.
    std::vector<double> w(candidates.size(), 1.0);
    if (!apply_log_likelihoods(w, cand_l, params_.likelihood_power)) w.assign(w.size(), 1.0);
    challenger_.clear();
    for (std::size_t i : resample_indices(w, std::max<std::size_t>(drawn_from_sensor(), 1), params_.resampling, rng_)) {
      challenger_.push_back(candidates[i]);
    }
    return false;
  }
  mix_in(model, candidates, cand_l);
  return true;
}

bool MonteCarloLocalization::confirm_challenger(const SensorModel& model, const CloudScore& cloud) {
  std::vector<Pose2> held;
  held.swap(challenger_);
  const std::vector<double> l = evaluate(model, held);
  if (!explains_better(*std::max_element(l.begin(), l.end()), cloud.best_log_likelihood) ||
      !agrees_at(model, held, l, cloud)) {
    return false;
  }
  mix_in(model, held, l);
  return true;
}

void MonteCarloLocalization::mix_in(const SensorModel& model, const std::vector<Pose2>& proposed,
                                    const std::vector<double>& log_l) {
  const std::size_t n = particles_.size(), from_sensor = drawn_from_sensor();
  std::vector<double> w(proposed.size(), 1.0);
  std::vector<Pose2> out;
  out.reserve(n);
  if (from_sensor < n) {
    for (std::size_t i : resample_indices(weights_, n - from_sensor, params_.resampling, rng_)) out.push_back(particles_[i]);
  }
  if (from_sensor > 0) {
    if (!apply_log_likelihoods(w, log_l, params_.likelihood_power)) w.assign(w.size(), 1.0);
    for (std::size_t i : resample_indices(w, from_sensor, params_.resampling, rng_)) out.push_back(proposed[i]);
  }
  particles_.swap(out);
  weights_.assign(n, 1.0 / static_cast<double>(n));
  // Weigh the mixed set, so that the estimate is that of the better part, not the mean of two
  // places.
  apply_log_likelihoods(weights_, evaluate(model, particles_), params_.likelihood_power);
}

}  // namespace kiseki
