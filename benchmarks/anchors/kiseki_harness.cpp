// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// kiseki's Monte Carlo localization (kiseki_core, built from cpp/ with kiseki's own CMake
// flags) over one harness input (harness_io.hpp), driven as kiseki.filters.localize drives it
// when every scan is an update: predict by the odometry increment since the last scan (none at
// the first), give the model the scan (set_scan), update (weigh, resample). predict and update
// are timed; set_scan is not (it turns the beams into end points once per scan, as the ROS
// nodes' scan conversion the other harnesses leave untimed; on the first scan it also
// tabulates the field for the max range, as nav2 and beluga do when their models are made).
// The estimate is the engine's posterior (the weighted mean before resampling), the pose
// localize reports. --seed is the engine's seed (localize derives it from its own seed).
#include <memory>
#include <stdexcept>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "harness_io.hpp"

#include "kiseki/core/pose.hpp"
#include "kiseki/filters/monte_carlo_localization.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/models/beam_model.hpp"
#include "kiseki/models/likelihood_field.hpp"

namespace {

std::vector<harness::Step> run(const harness::Run& run) {
  const harness::Input& in = run.input;
  cv::Mat cells(in.height, in.width, CV_8SC1);
  std::copy(in.cells.begin(), in.cells.end(), cells.ptr<std::int8_t>(0));
  const kiseki::OccupancyGrid grid(cells, in.resolution, kiseki::Pose2(in.origin_x, in.origin_y, 0.0));
  const auto combination = run.combination == "nav2" ? kiseki::BeamCombination::nav2
                                                     : kiseki::BeamCombination::product;

  std::unique_ptr<kiseki::LikelihoodFieldModel> field;
  std::unique_ptr<kiseki::BeamModel> beam;
  if (run.model == "likelihood-field") {
    kiseki::LikelihoodFieldParams p;
    p.sigma_hit = in[harness::kSigmaHit];
    p.z_hit = in[harness::kZHit];
    p.z_rand = in[harness::kZRand];
    p.max_beams = 0;  // every beam given
    p.max_distance = in[harness::kLikelihoodMaxDist];
    p.combination = combination;
    field = std::make_unique<kiseki::LikelihoodFieldModel>(grid, p);
  } else {
    kiseki::BeamModelParams p;
    p.z_hit = in[harness::kZHit], p.z_short = in[harness::kZShort];
    p.z_max = in[harness::kZMax], p.z_rand = in[harness::kZRand];
    p.sigma_hit = in[harness::kSigmaHit], p.lambda_short = in[harness::kLambdaShort];
    p.max_beams = 0;
    p.combination = combination;
    beam = std::make_unique<kiseki::BeamModel>(grid, p);
  }

  kiseki::MclParams params;
  params.particles = static_cast<std::size_t>(run.particles);
  params.kld = false;
  params.motion.type = kiseki::MotionModelType::differential;
  params.motion.alpha1 = in[harness::kAlpha1], params.motion.alpha2 = in[harness::kAlpha2];
  params.motion.alpha3 = in[harness::kAlpha3], params.motion.alpha4 = in[harness::kAlpha4];
  params.resampling = kiseki::ResamplingMethod::multinomial;  // as nav2 and beluga
  params.resample_threshold = 1.0;                            // every update
  params.recovery = kiseki::Recovery::none;
  params.threads = run.threads;
  params.validate();
  kiseki::MonteCarloLocalization mcl(params, run.seed);
  mcl.initialize_gaussian(
      kiseki::Pose2(in[harness::kInitialX], in[harness::kInitialY], in[harness::kInitialTheta]),
      in[harness::kInitialSdX], in[harness::kInitialSdY], in[harness::kInitialSdTheta]);

  std::vector<harness::Step> steps;
  steps.reserve(in.scans);
  for (int k = 0; k < in.scans; ++k) {
    if (field) field->set_scan(in.angles.data(), in.scan(k), in.angles.size(), in.max_range);
    if (beam) beam->set_scan(in.angles.data(), in.scan(k), in.angles.size(), in.max_range);
    const kiseki::SensorModel& model = field ? static_cast<const kiseki::SensorModel&>(*field) : *beam;
    const double* before = in.odom(k > 0 ? k - 1 : 0);
    const double* after = in.odom(k);

    const auto start = harness::Clock::now();
    if (k > 0)
      mcl.predict(kiseki::Pose2(before[0], before[1], before[2]), kiseki::Pose2(after[0], after[1], after[2]));
    mcl.update(model);
    const auto stop = harness::Clock::now();

    const kiseki::Pose2& estimate = mcl.posterior();
    steps.push_back({estimate.x, estimate.y, estimate.theta, harness::seconds_between(start, stop)});
  }
  return steps;
}

}  // namespace

int main(int argc, char** argv) { return harness::harness_main(argc, argv, run); }
