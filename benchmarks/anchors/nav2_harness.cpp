// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// nav2 AMCL's particle filter, map, differential motion model and laser models, built from
// nav2_amcl's unmodified sources, driven over one harness input (harness_io.hpp) as nav2's
// amcl_node drives them on each scan: odometryUpdate (the increment since the last update),
// the laser model's sensorUpdate, pf_update_resample (resample_interval 1). Only those three
// calls are timed; the scan's conversion to LaserData (the node's work) is not.
//
// Set-up as in amcl_node.cpp: the map converted as its convertMap does (ROS values 0 / 100 /
// other to free / occupied / unknown; the node takes the message origin as the centre of cell
// 0, so the corner origin of the input is moved by half a cell); srand48(seed) before pf_init
// (its random_seed parameter); readings at or below range_min (0 here) set to range_max; the
// estimate is the mean of the heaviest cluster (the node's published pose). nav2's filter is
// single-threaded: --threads must be 1.
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "harness_io.hpp"

#include "nav2_amcl/angleutils.hpp"
#include "nav2_amcl/map/map.hpp"
#include "nav2_amcl/motion_model/differential_motion_model.hpp"
#include "nav2_amcl/pf/pf.hpp"
#include "nav2_amcl/sensors/laser/laser.hpp"

namespace {

// The free cells uniform poses would be drawn from (recovery is off: alpha_slow = alpha_fast
// = 0, so the filter never calls this; pf_alloc needs one).
std::vector<pf_vector_t> free_poses;

pf_vector_t uniform_pose(void*) {
  pf_vector_t pose = free_poses[static_cast<std::size_t>(drand48() * free_poses.size())];
  pose.v[2] = drand48() * 2 * M_PI - M_PI;
  return pose;
}

map_t* convert_map(const harness::Input& in) {
  map_t* map = map_alloc();
  map->size_x = in.width;
  map->size_y = in.height;
  map->scale = in.resolution;
  const double ros_origin_x = in.origin_x + 0.5 * in.resolution;
  const double ros_origin_y = in.origin_y + 0.5 * in.resolution;
  map->origin_x = ros_origin_x + (map->size_x / 2) * map->scale;
  map->origin_y = ros_origin_y + (map->size_y / 2) * map->scale;
  map->cells = static_cast<map_cell_t*>(malloc(sizeof(map_cell_t) * in.cells.size()));
  for (std::size_t i = 0; i < in.cells.size(); ++i) {
    const int value = in.cells[i];
    map->cells[i].occ_state = value == 0 ? -1 : value == 100 ? +1 : 0;
    if (value == 0) {
      pf_vector_t pose = pf_vector_zero();
      pose.v[0] = ros_origin_x + static_cast<double>(i % in.width) * in.resolution;
      pose.v[1] = ros_origin_y + static_cast<double>(i / in.width) * in.resolution;
      free_poses.push_back(pose);
    }
  }
  return map;
}

pf_vector_t heaviest_cluster_mean(pf_t* pf) {
  double best = 0.0;
  pf_vector_t best_mean = pf_vector_zero();
  for (int c = 0; c < pf->sets[pf->current_set].cluster_count; ++c) {
    double weight = 0.0;
    pf_vector_t mean;
    pf_matrix_t cov;
    if (pf_get_cluster_stats(pf, c, &weight, &mean, &cov) && weight > best) {
      best = weight;
      best_mean = mean;
    }
  }
  return best_mean;
}

std::vector<harness::Step> run(const harness::Run& run) {
  const harness::Input& in = run.input;
  using harness::Parameter;
  if (run.threads != 1) throw std::runtime_error("nav2 AMCL is single-threaded: --threads 1");
  if (run.combination != "nav2")
    throw std::runtime_error("nav2 AMCL combines beams only as 1 + sum pz^3: --combination nav2");
  map_t* map = convert_map(in);
  const int n = static_cast<int>(run.particles);
  pf_t* pf = pf_alloc(n, n, 0.0, 0.0, uniform_pose);
  srand48(static_cast<long>(run.seed));
  pf_vector_t mean = pf_vector_zero();
  mean.v[0] = in[harness::kInitialX], mean.v[1] = in[harness::kInitialY];
  mean.v[2] = in[harness::kInitialTheta];
  pf_matrix_t cov = pf_matrix_zero();
  cov.m[0][0] = in[harness::kInitialSdX] * in[harness::kInitialSdX];
  cov.m[1][1] = in[harness::kInitialSdY] * in[harness::kInitialSdY];
  cov.m[2][2] = in[harness::kInitialSdTheta] * in[harness::kInitialSdTheta];
  pf_init(pf, mean, cov);

  nav2_amcl::DifferentialMotionModel motion;
  motion.initialize(in[harness::kAlpha1], in[harness::kAlpha2], in[harness::kAlpha3],
                    in[harness::kAlpha4], 0.0);
  nav2_amcl::Laser* laser = nullptr;
  const auto beams = static_cast<std::size_t>(in.beams);  // max_beams: every beam given
  if (run.model == "likelihood-field") {
    laser = new nav2_amcl::LikelihoodFieldModel(in[harness::kZHit], in[harness::kZRand],
                                                in[harness::kSigmaHit],
                                                in[harness::kLikelihoodMaxDist], beams, map);
  } else {
    laser = new nav2_amcl::BeamModel(in[harness::kZHit], in[harness::kZShort], in[harness::kZMax],
                                     in[harness::kZRand], in[harness::kSigmaHit],
                                     in[harness::kLambdaShort], 0.0, beams, map);
  }
  pf_vector_t laser_pose = pf_vector_zero();  // the odometry is the laser's
  laser->SetLaserPose(laser_pose);

  std::vector<harness::Step> steps;
  steps.reserve(in.scans);
  pf_vector_t last = pf_vector_zero();
  for (int k = 0; k < in.scans; ++k) {
    nav2_amcl::LaserData data;
    data.laser = laser;
    data.range_count = in.beams;
    data.range_max = in.max_range;
    data.ranges = new double[in.beams][2];
    const float* ranges = in.scan(k);
    for (int i = 0; i < in.beams; ++i) {
      data.ranges[i][0] = ranges[i] <= 0.0f ? in.max_range : static_cast<double>(ranges[i]);
      data.ranges[i][1] = in.angles[i];
    }
    pf_vector_t pose = pf_vector_zero();
    pose.v[0] = in.odom(k)[0], pose.v[1] = in.odom(k)[1], pose.v[2] = in.odom(k)[2];
    pf_vector_t delta = pf_vector_zero();
    delta.v[0] = pose.v[0] - last.v[0];
    delta.v[1] = pose.v[1] - last.v[1];
    delta.v[2] = nav2_amcl::angleutils::angle_diff(pose.v[2], last.v[2]);

    const auto start = harness::Clock::now();
    if (k > 0) motion.odometryUpdate(pf, pose, delta);
    laser->sensorUpdate(pf, &data);
    pf_update_resample(pf, map);
    const auto stop = harness::Clock::now();

    last = pose;
    const pf_vector_t estimate = heaviest_cluster_mean(pf);
    steps.push_back({estimate.v[0], estimate.v[1], estimate.v[2], harness::seconds_between(start, stop)});
  }
  delete laser;
  pf_free(pf);
  map_free(map);
  return steps;
}

}  // namespace

int main(int argc, char** argv) { return harness::harness_main(argc, argv, run); }
