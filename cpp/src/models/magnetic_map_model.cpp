// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/magnetic_map_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kiseki {

namespace {
constexpr double kLog2Pi = 1.8378770664093454836;
}

void MagneticGrid::validate() const {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) throw std::invalid_argument("magnetic grid: resolution must be > 0");
  if (!std::isfinite(origin_x) || !std::isfinite(origin_y)) throw std::invalid_argument("magnetic grid: origin must be finite");
  if (width < 1 || height < 1) throw std::invalid_argument("magnetic grid: needs at least one cell");
  const auto cells = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3;
  if (mean.size() != cells || variance.size() != cells) {
    throw std::invalid_argument("magnetic grid: mean and variance must hold height x width x 3 values");
  }
  for (std::size_t i = 0; i < cells; ++i) {
    if (!std::isfinite(mean[i])) throw std::invalid_argument("magnetic grid: the mean has NaN or infinite values");
    if (!std::isfinite(variance[i]) || variance[i] < 0.0) {
      throw std::invalid_argument("magnetic grid: the variance has negative, NaN or infinite values");
    }
  }
  if (!prior_mean.allFinite() || !prior_variance.allFinite() || prior_variance.minCoeff() <= 0.0) {
    throw std::invalid_argument("magnetic grid: the prior mean must be finite and the prior variance > 0");
  }
}

void MagneticGrid::value_at(double x, double y, Eigen::Vector3d& mean_out, Eigen::Vector3d& variance_out) const {
  // Continuous cell coordinates of the point, cell centres at integers.
  const double u = (x - origin_x) / resolution - 0.5;
  const double v = (y - origin_y) / resolution - 0.5;
  if (!(u >= -1.0 && v >= -1.0 && u <= width && v <= height)) {  // also false for NaN
    mean_out = prior_mean;
    variance_out = prior_variance;
    return;
  }
  const double uc = std::min(std::max(u, 0.0), static_cast<double>(width - 1));
  const double vc = std::min(std::max(v, 0.0), static_cast<double>(height - 1));
  const int i0 = std::min(static_cast<int>(std::floor(uc)), width - 1);
  const int j0 = std::min(static_cast<int>(std::floor(vc)), height - 1);
  const int i1 = std::min(i0 + 1, width - 1);
  const int j1 = std::min(j0 + 1, height - 1);
  const double a = uc - i0;
  const double b = vc - j0;
  const auto at = [&](const std::vector<double>& layer, int i, int j, int c) {
    return layer[(static_cast<std::size_t>(j) * static_cast<std::size_t>(width) + static_cast<std::size_t>(i)) * 3 +
                 static_cast<std::size_t>(c)];
  };
  for (int c = 0; c < 3; ++c) {
    mean_out(c) = (1 - a) * (1 - b) * at(mean, i0, j0, c) + a * (1 - b) * at(mean, i1, j0, c) +
                  (1 - a) * b * at(mean, i0, j1, c) + a * b * at(mean, i1, j1, c);
    variance_out(c) = (1 - a) * (1 - b) * at(variance, i0, j0, c) + a * (1 - b) * at(variance, i1, j0, c) +
                      (1 - a) * b * at(variance, i0, j1, c) + a * b * at(variance, i1, j1, c);
  }
}

MagneticMapModel::MagneticMapModel(MagneticGrid grid, std::vector<Eigen::Vector2d> offsets, double noise_sd,
                                   bool world_frame)
    : grid_(std::move(grid)), offsets_(std::move(offsets)), noise_variance_(noise_sd * noise_sd),
      world_frame_(world_frame) {
  grid_.validate();
  if (offsets_.empty()) throw std::invalid_argument("magnetic map model: needs at least one sensor");
  for (const auto& o : offsets_) {
    if (!o.allFinite()) throw std::invalid_argument("magnetic map model: sensor offsets must be finite");
  }
  if (!(noise_sd >= 0.0) || !std::isfinite(noise_sd)) throw std::invalid_argument("magnetic map model: noise_sd must be >= 0");
}

void MagneticMapModel::set_readings(const std::vector<Eigen::Vector3d>& readings) {
  if (readings.size() != offsets_.size()) {
    throw std::invalid_argument("magnetic map model: " + std::to_string(readings.size()) + " readings for " +
                                std::to_string(offsets_.size()) + " sensors");
  }
  for (const auto& r : readings) {
    if (!r.allFinite()) throw std::invalid_argument("magnetic map model: a reading is NaN or infinite");
  }
  readings_ = readings;
}

void MagneticMapModel::log_likelihoods(const Pose2* poses, std::size_t n, double* out) const {
  if (readings_.empty()) throw std::logic_error("magnetic map model: set_readings() before the update");
  Eigen::Vector3d mu;
  Eigen::Vector3d var;
  for (std::size_t k = 0; k < n; ++k) {
    const double c = std::cos(poses[k].theta);
    const double s = std::sin(poses[k].theta);
    double sum = 0.0;
    for (std::size_t i = 0; i < offsets_.size(); ++i) {
      const Eigen::Vector2d& o = offsets_[i];
      const double x = poses[k].x + c * o.x() - s * o.y();
      const double y = poses[k].y + s * o.x() + c * o.y();
      grid_.value_at(x, y, mu, var);
      Eigen::Vector3d z = readings_[i];
      if (!world_frame_) z = Eigen::Vector3d(c * z.x() - s * z.y(), s * z.x() + c * z.y(), z.z());
      for (int a = 0; a < 3; ++a) {  // eq. 6.17 with a diagonal covariance; eq. 6.18's product
        const double sc = std::max(var(a) + noise_variance_, 1e-12 * grid_.prior_variance(a));
        const double e = z(a) - mu(a);
        sum += -0.5 * e * e / sc - 0.5 * (kLog2Pi + std::log(sc));
      }
    }
    out[k] = sum;
  }
}

}  // namespace kiseki
