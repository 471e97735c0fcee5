// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/filters/sensor_reset_proposal.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "kiseki/core/angle.hpp"

namespace kiseki {

ResetProposal reset_proposal_from_name(const std::string& name) {
  if (name == "uniform") return ResetProposal::uniform;
  if (name == "matcher") return ResetProposal::matcher;
  throw std::invalid_argument("sensor_reset_proposal: unknown '" + name + "' (uniform or matcher)");
}

const char* reset_proposal_name(ResetProposal proposal) {
  return proposal == ResetProposal::matcher ? "matcher" : "uniform";
}

std::vector<Pose2> poses_around_hypotheses(const std::vector<PoseHypothesis>& hypotheses, std::size_t count,
                                           double sd_xy, double sd_theta, double power, Random& rng) {
  if (hypotheses.empty()) throw std::invalid_argument("sensor reset: no hypotheses to draw poses around");
  if (!(sd_xy >= 0.0 && sd_theta >= 0.0 && std::isfinite(sd_xy + sd_theta))) {
    throw std::invalid_argument("sensor reset: the spreads around hypotheses must be finite and >= 0");
  }
  const std::size_t k = hypotheses.size();
  double best = hypotheses[0].score;
  for (const auto& h : hypotheses) best = std::max(best, h.score);
  std::vector<double> share(k);
  double total = 0.0;
  for (std::size_t i = 0; i < k; ++i) total += share[i] = std::exp(power * (hypotheses[i].score - best));
  std::vector<std::size_t> n(k);
  std::size_t given = 0;
  for (std::size_t i = 0; i < k; ++i) {
    share[i] *= static_cast<double>(count) / total;
    given += n[i] = static_cast<std::size_t>(std::floor(share[i]));
  }
  // largest remainders first (stable: the better rank on a tie)
  std::vector<std::size_t> order(k);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return share[a] - std::floor(share[a]) > share[b] - std::floor(share[b]);
  });
  for (std::size_t i = 0; given < count; ++i, ++given) ++n[order[i % k]];
  std::vector<Pose2> out;
  out.reserve(count);
  for (std::size_t i = 0; i < k; ++i) {
    const Pose2& c = hypotheses[i].pose;
    for (std::size_t j = 0; j < n[i]; ++j) {
      const double x = rng.normal(c.x, sd_xy), y = rng.normal(c.y, sd_xy);
      out.emplace_back(x, y, normalize_angle(rng.normal(c.theta, sd_theta)));
    }
  }
  return out;
}

double look_elsewhere_term(double searched) { return std::log(std::max(searched, 1.0)); }

}  // namespace kiseki
