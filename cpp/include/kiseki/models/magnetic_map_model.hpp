// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <Eigen/Core>
#include <vector>

#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// A 2-D magnetic field map: the mean and variance of the field's three world-frame components
/// (x, y, z) on square cells, row 0 at the lowest y, values at the cell centres; outside the
/// cells the field's prior (a GP map's mean function and sigma_f^2).
struct MagneticGrid {
  double origin_x = 0.0;  ///< the lower-left corner of cell (0, 0), m
  double origin_y = 0.0;
  double resolution = 0.1;  ///< m
  int width = 0;            ///< cells along x
  int height = 0;           ///< cells along y
  std::vector<double> mean;      ///< height x width x 3, row-major
  std::vector<double> variance;  ///< the same layout, >= 0
  Eigen::Vector3d prior_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d prior_variance = Eigen::Vector3d::Ones();

  /// Throws std::invalid_argument for sizes that disagree, NaN or negative variances.
  void validate() const;
  /// Bilinear interpolation between the cell centres; the prior beyond half a cell outside them.
  void value_at(double x, double y, Eigen::Vector3d& mean_out, Eigen::Vector3d& variance_out) const;
};

/// The magnetic-map measurement model of the magnetic-navigation thesis (chapter 6, eqs.
/// 6.17-6.18): each magnetometer's reading z_i = (mx, my, mz) is Gaussian about the map's mean at
/// the sensor's position, with the map's variance plus the sensor's noise sigma^2 on the diagonal,
/// and the sensors are independent:
///   log p(z | x) = sum_i sum_c [-(z_ic - mu_c(x_i))^2 / (2 s_c) - log(2 pi s_c) / 2],
///   s_c = var_c(x_i) + sigma^2.
/// The thesis writes Sigma_x for the GP's variance; the reading also carries the sensor's noise,
/// which kiseki adds (with sigma = 0 the model is the thesis' literally).
///
/// Readings are given in the robot's body frame (x forward, y left, z up; convert a sensor's
/// x-forward/y-right/z-down reading by negating y and z) and turned into the world frame by each
/// particle's heading, which is how the field's direction corrects the heading; or, for data
/// already in the world frame (the Aalto recordings), used as they are.
class MagneticMapModel : public SensorModel {
 public:
  /// offsets: each sensor's (x, y) in the body frame, m.
  MagneticMapModel(MagneticGrid grid, std::vector<Eigen::Vector2d> offsets, double noise_sd, bool world_frame = false);

  /// One reading per sensor (s x 3, in the order of the offsets).
  void set_readings(const std::vector<Eigen::Vector3d>& readings);
  void log_likelihoods(const Pose2* poses, std::size_t n, double* out) const override;
  std::size_t readings() const override { return offsets_.size(); }
  const MagneticGrid& grid() const { return grid_; }

 private:
  MagneticGrid grid_;
  std::vector<Eigen::Vector2d> offsets_;
  double noise_variance_;
  bool world_frame_;
  std::vector<Eigen::Vector3d> readings_;
};

}  // namespace kiseki
