// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// beluga's AMCL (beluga::Amcl of its header-only core, unmodified) over one harness input
// (harness_io.hpp): the differential drive model, the likelihood field or beam model, KLD
// resampling held at a fixed count (min = max particles), every scan an update
// (force_update) and a resampling at every update (resample_interval 1, no selective
// resampling), recovery off (alpha_slow = alpha_fast = 0). Only Amcl::update is timed (it
// moves, weighs, normalises, resamples and returns the weighted mean of the particles, the
// estimate written out).
//
// Set-up as beluga_amcl does from nav2's parameter names: alpha1..alpha4 as rotation from
// rotation, rotation from translation, translation from translation, translation from rotation;
// the likelihood field's max_obstacle_distance = laser_likelihood_max_dist and
// max_laser_distance = the laser's max range; the scan as points in the laser frame, without
// its invalid and no-return readings for the likelihood field (the model would take them as
// hits) and with no-return readings at max range for the beam model. One thread runs the
// sequenced policy; more run std::execution::par (TBB) limited by tbb::global_control. The
// seed seeds range-v3's per-thread engine of the calling thread, which beluga draws from;
// worker threads' engines are beluga's own (seeded from std::random_device), so runs on more
// than one thread are not repeatable.
#include <cmath>
#include <cstdint>
#include <execution>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tbb/global_control.h>

#include <beluga/algorithm/amcl_core.hpp>
#include <beluga/algorithm/spatial_hash.hpp>
#include <beluga/motion/differential_drive_model.hpp>
#include <beluga/sensor/beam_model.hpp>
#include <beluga/sensor/data/occupancy_grid.hpp>
#include <beluga/sensor/likelihood_field_model.hpp>
#include <range/v3/utility/random.hpp>
#include <sophus/se2.hpp>

#include "harness_io.hpp"

namespace {

/// The input's cells (0 free, 100 occupied, -1 unknown) as a beluga occupancy grid; its
/// origin is the corner of cell 0, as beluga takes a ROS map's origin.
class Grid : public beluga::BaseOccupancyGrid2<Grid> {
 public:
  struct ValueTraits {
    [[nodiscard]] bool is_free(std::int8_t value) const { return value == 0; }
    [[nodiscard]] bool is_unknown(std::int8_t value) const { return value != 0 && value != 100; }
    [[nodiscard]] bool is_occupied(std::int8_t value) const { return value == 100; }
  };

  explicit Grid(const harness::Input& in)
      : cells_{in.cells},
        width_{static_cast<std::size_t>(in.width)},
        height_{static_cast<std::size_t>(in.height)},
        resolution_{in.resolution},
        origin_{Sophus::SO2d{}, Eigen::Vector2d{in.origin_x, in.origin_y}} {}

  [[nodiscard]] const Sophus::SE2d& origin() const { return origin_; }
  [[nodiscard]] const std::vector<std::int8_t>& data() const { return cells_; }
  [[nodiscard]] std::size_t size() const { return cells_.size(); }
  [[nodiscard]] std::size_t width() const { return width_; }
  [[nodiscard]] std::size_t height() const { return height_; }
  [[nodiscard]] double resolution() const { return resolution_; }
  [[nodiscard]] ValueTraits value_traits() const { return {}; }

 private:
  std::vector<std::int8_t> cells_;
  std::size_t width_, height_;
  double resolution_;
  Sophus::SE2d origin_;
};

using Measurement = std::vector<std::pair<double, double>>;

Measurement points_of(const harness::Input& in, int k, bool keep_no_return) {
  Measurement points;
  const float* ranges = in.scan(k);
  for (int i = 0; i < in.beams; ++i) {
    double r = ranges[i];
    if (!(r > 0.0)) continue;  // NaN or non-positive: no valid reading
    if (r >= in.max_range) {
      if (!keep_no_return) continue;
      r = in.max_range;
    }
    points.emplace_back(r * std::cos(in.angles[i]), r * std::sin(in.angles[i]));
  }
  return points;
}

Sophus::SE2d pose_of(const double* p) { return Sophus::SE2d{p[2], Eigen::Vector2d{p[0], p[1]}}; }

template <class SensorModel, class Policy>
std::vector<harness::Step> track(const harness::Run& run, SensorModel sensor, Policy policy,
                                 bool keep_no_return) {
  const harness::Input& in = run.input;
  beluga::DifferentialDriveModelParam motion_params;
  motion_params.rotation_noise_from_rotation = in[harness::kAlpha1];
  motion_params.rotation_noise_from_translation = in[harness::kAlpha2];
  motion_params.translation_noise_from_translation = in[harness::kAlpha3];
  motion_params.translation_noise_from_rotation = in[harness::kAlpha4];

  beluga::AmclParams params;
  params.update_min_d = 0.0;
  params.update_min_a = 0.0;
  params.resample_interval = 1;
  params.selective_resampling = false;
  params.min_particles = static_cast<std::size_t>(run.particles);
  params.max_particles = static_cast<std::size_t>(run.particles);
  params.alpha_slow = 0.0;
  params.alpha_fast = 0.0;

  const Grid grid{in};
  auto free = grid.free_cells() | ranges::to<std::vector<std::size_t>>;
  // Recovery is off, so Amcl never draws a random state; it needs a generator all the same.
  auto random_state = [&grid, free]() {
    auto& engine = ranges::detail::get_random_engine();
    const auto cell = free[std::uniform_int_distribution<std::size_t>{0, free.size() - 1}(engine)];
    const double theta = std::uniform_real_distribution<double>{-M_PI, M_PI}(engine);
    return Sophus::SE2d{theta, grid.coordinates_at(cell, Grid::Frame::kGlobal)};
  };
  // beluga_amcl's defaults: 0.5 m cells, 10 degrees
  const auto hasher = beluga::spatial_hash<Sophus::SE2d>{0.5, 10.0 * M_PI / 180.0};

  beluga::Amcl<beluga::DifferentialDriveModel2d, SensorModel, decltype(random_state), beluga::Weight,
               std::tuple<Sophus::SE2d, beluga::Weight>, Policy>
      amcl{beluga::DifferentialDriveModel2d{motion_params}, std::move(sensor), random_state, hasher,
           params, policy};

  ranges::detail::get_random_engine().seed(static_cast<std::uint32_t>(run.seed));
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  covariance(0, 0) = in[harness::kInitialSdX] * in[harness::kInitialSdX];
  covariance(1, 1) = in[harness::kInitialSdY] * in[harness::kInitialSdY];
  covariance(2, 2) = in[harness::kInitialSdTheta] * in[harness::kInitialSdTheta];
  const double initial[3] = {in[harness::kInitialX], in[harness::kInitialY], in[harness::kInitialTheta]};
  amcl.initialize(pose_of(initial), covariance);

  std::vector<harness::Step> steps;
  steps.reserve(in.scans);
  for (int k = 0; k < in.scans; ++k) {
    Measurement points = points_of(in, k, keep_no_return);
    const Sophus::SE2d odom = pose_of(in.odom(k));
    amcl.force_update();  // every scan an update, moved or not

    const auto start = harness::Clock::now();
    const auto estimate = amcl.update(odom, std::move(points));
    const auto stop = harness::Clock::now();

    if (!estimate) throw std::runtime_error("beluga made no update at scan " + std::to_string(k));
    const Sophus::SE2d& pose = estimate->first;
    steps.push_back({pose.translation().x(), pose.translation().y(), pose.so2().log(),
                     harness::seconds_between(start, stop)});
  }
  return steps;
}

template <class Policy>
std::vector<harness::Step> run_with(const harness::Run& run, Policy policy) {
  const harness::Input& in = run.input;
  const Grid grid{in};
  if (run.model == "likelihood-field") {
    beluga::LikelihoodFieldModelParam params;
    params.max_obstacle_distance = in[harness::kLikelihoodMaxDist];
    params.max_laser_distance = in.max_range;
    params.z_hit = in[harness::kZHit];
    params.z_random = in[harness::kZRand];
    params.sigma_hit = in[harness::kSigmaHit];
    return track(run, beluga::LikelihoodFieldModel<Grid>{params, grid}, policy, false);
  }
  beluga::BeamModelParam params;
  params.z_hit = in[harness::kZHit];
  params.z_short = in[harness::kZShort];
  params.z_max = in[harness::kZMax];
  params.z_rand = in[harness::kZRand];
  params.sigma_hit = in[harness::kSigmaHit];
  params.lambda_short = in[harness::kLambdaShort];
  params.beam_max_range = in.max_range;
  return track(run, beluga::BeamSensorModel<Grid>{params, grid}, policy, true);
}

std::vector<harness::Step> run(const harness::Run& run) {
  if (run.combination != "nav2")
    throw std::runtime_error("beluga combines beams only as 1 + sum pz^3: --combination nav2");
  if (run.threads == 1) return run_with(run, std::execution::seq);
  tbb::global_control threads{tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(run.threads)};
  return run_with(run, std::execution::par);
}

}  // namespace

int main(int argc, char** argv) { return harness::harness_main(argc, argv, run); }
