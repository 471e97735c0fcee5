// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>

#include "kiseki/models/beam_model.hpp"
#include "kiseki/models/likelihood_field.hpp"
#include "kiseki/models/local_map.hpp"
#include "kiseki/models/magnetic_map_model.hpp"
#include "kiseki/models/ray_space_observation.hpp"
#include "kiseki/models/space_observation.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

Pose3 pose3_from_matrix(const Eigen::Matrix4d& m) {
  const Eigen::Matrix3d r = m.block<3, 3>(0, 0);
  if (!m.allFinite() || !(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      r.determinant() < 0) {
    throw std::invalid_argument("pose: expected a finite 4x4 rigid transform");
  }
  return {m.block<3, 1>(0, 3), Eigen::Quaterniond(r)};
}

// One value per pose of a checked (n, 3) pose array, computed by fn(poses, n, out) without the GIL.
template <typename Fn>
py::array_t<double> per_pose(const py::handle& poses_in, Fn&& fn) {
  const auto p = as_doubles(poses_in, "poses");
  require_shape(p, "poses", 2, 3);
  require_finite(p, "poses");
  py::array_t<double> out(p.shape(0));
  double* dst = out.mutable_data();
  {
    py::gil_scoped_release release;
    fn(p.data(), static_cast<std::size_t>(p.shape(0)), dst);
  }
  return out;
}

void add_scan(LocalMapBuilder& b, const Pose2& sensor, const py::handle& a_in,
              const py::handle& r_in, double max_range) {
  const auto [a, r] = beams(a_in, r_in);
  b.add_scan(sensor, a.data(), r.data(), static_cast<std::size_t>(a.shape(0)), max_range);
}

}  // namespace

void bind_models(py::module_& m) {
  py::class_<LocalMapBuilder>(m, "LocalMapBuilder")
      .def(py::init([](double size, double resolution) {
             return LocalMapBuilder(LocalMapParams{size, resolution});
           }),
           "size"_a = 8.0, "resolution"_a = 0.1)
      .def("add_scan", &add_scan, "sensor"_a, "angles"_a, "ranges"_a, "max_range"_a)
      .def(
          "add_depth_band",
          [](LocalMapBuilder& b, const py::array& depth_in, const Eigen::Matrix4d& optical,
             int width, int height, double fx, double fy, double cx, double cy, double min_range,
             double max_range, double z_min, double z_max) {
            const auto d = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(depth_in);
            if (!d || d.ndim() != 2) throw std::invalid_argument("depth: expected a 2-D float32 image");
            const PinholeCamera cam{width, height, fx, fy, cx, cy, min_range, max_range};
            const cv::Mat view(static_cast<int>(d.shape(0)), static_cast<int>(d.shape(1)), CV_32FC1,
                               const_cast<float*>(d.data()));
            b.add_depth_band(view, cam, pose3_from_matrix(optical), z_min, z_max);
          },
          "depth"_a, "optical_in_robot"_a, "width"_a, "height"_a, "fx"_a, "fy"_a, "cx"_a, "cy"_a,
          "min_range"_a,
          "max_range"_a, "z_min"_a, "z_max"_a)
      .def("build", &LocalMapBuilder::build)
      .def("hits", [](const LocalMapBuilder& b) { return mat_to_numpy(b.hits()); },
           "The cells a beam ended in (uint8 mask, 1 = hit), of build()'s size.");

  py::class_<SensorModel>(m, "SensorModel",
                          "A measurement model of the Monte Carlo engine: log p(z | x) per pose.")
      .def("log_likelihoods",
           [](const SensorModel& sm, const py::handle& poses) {
             return per_pose(poses, [&](const double* p, std::size_t n, double* out) {
               std::vector<Pose2> q(n);
               for (std::size_t i = 0; i < n; ++i) q[i] = pose_from_row(p + 3 * i);
               sm.log_likelihoods(q.data(), n, out);
             });
           }, "poses"_a, "Log-likelihoods of robot poses (n, 3) on one thread; releases the GIL.")
      .def("agreement", &SensorModel::agreement, "pose"_a,
           "Share of the measurement that agrees with the map from this pose (NaN: unknown).")
      .def_property_readonly("readings", &SensorModel::readings);

  py::class_<MagneticMapModel, SensorModel>(m, "MagneticMapModel",
                                            "Eqs. 6.17-6.18 of the magnetic thesis on a 2-D field map (see "
                                            "kiseki.magnetic.MagneticMapModel).")
      .def(py::init([](const py::handle& mean, const py::handle& variance, double origin_x, double origin_y,
                       double resolution, const Eigen::Vector3d& prior_mean, const Eigen::Vector3d& prior_variance,
                       const py::handle& offsets, double noise_sd, bool world_frame) {
             const DoubleArray mu = as_doubles(mean, "mean");
             const DoubleArray var = as_doubles(variance, "variance");
             if (mu.ndim() != 3 || mu.shape(2) != 3) {
               throw std::invalid_argument("mean: expected shape (height, width, 3), got " + shape_string(mu));
             }
             if (var.ndim() != 3 || var.shape(0) != mu.shape(0) || var.shape(1) != mu.shape(1) || var.shape(2) != 3) {
               throw std::invalid_argument("variance: expected the mean's shape " + shape_string(mu) + ", got " +
                                           shape_string(var));
             }
             const DoubleArray off = as_doubles(offsets, "offsets");
             require_shape(off, "offsets", 2, 2);
             MagneticGrid g;
             g.origin_x = origin_x;
             g.origin_y = origin_y;
             g.resolution = resolution;
             g.height = static_cast<int>(mu.shape(0));
             g.width = static_cast<int>(mu.shape(1));
             g.mean.assign(mu.data(), mu.data() + mu.size());
             g.variance.assign(var.data(), var.data() + var.size());
             g.prior_mean = prior_mean;
             g.prior_variance = prior_variance;
             std::vector<Eigen::Vector2d> o;
             for (py::ssize_t i = 0; i < off.shape(0); ++i) o.emplace_back(off.at(i, 0), off.at(i, 1));
             return std::make_unique<MagneticMapModel>(std::move(g), std::move(o), noise_sd, world_frame);
           }),
           "mean"_a, "variance"_a, "origin_x"_a, "origin_y"_a, "resolution"_a, "prior_mean"_a, "prior_variance"_a,
           "offsets"_a, "noise_sd"_a, "world_frame"_a = false)
      .def(
          "set_readings",
          [](MagneticMapModel& model, const py::handle& readings) {
            const DoubleArray r = as_doubles(readings, "readings");
            require_shape(r, "readings", 2, 3);
            std::vector<Eigen::Vector3d> v;
            for (py::ssize_t i = 0; i < r.shape(0); ++i) v.emplace_back(r.at(i, 0), r.at(i, 1), r.at(i, 2));
            model.set_readings(v);
          },
          "readings"_a, "One (mx, my, mz) per sensor: body frame (x forward, y left, z up) unless world_frame.");

  py::enum_<BeamCombination>(m, "BeamCombination")
      .value("product", BeamCombination::product)
      .value("nav2", BeamCombination::nav2);

  py::class_<LikelihoodFieldModel, SensorModel>(m, "LikelihoodFieldModel")
      .def(py::init([](const OccupancyGrid& map, double sigma, double z_hit, double z_rand,
                       int max_beams, double max_distance, BeamCombination combination,
                       const Pose2& sensor, double tolerance, bool beam_skip, double skip_distance,
                       double skip_threshold, double skip_error_threshold) {
             LikelihoodFieldParams p;
             p.sigma_hit = sigma, p.z_hit = z_hit, p.z_rand = z_rand, p.max_beams = max_beams;
             p.max_distance = max_distance, p.combination = combination, p.sensor = sensor;
             p.agreement_tolerance = tolerance, p.beam_skip = beam_skip;
             p.beam_skip_distance = skip_distance, p.beam_skip_threshold = skip_threshold;
             p.beam_skip_error_threshold = skip_error_threshold;
             return std::make_unique<LikelihoodFieldModel>(map, p);
           }),
           "map"_a, "sigma_hit"_a = 0.2, "z_hit"_a = 0.95, "z_rand"_a = 0.05, "max_beams"_a = 0,
           "max_distance"_a = 2.0, "combination"_a = BeamCombination::product,
           "sensor"_a = Pose2(), "agreement_tolerance"_a = 0.2,
           "beam_skip"_a = LikelihoodFieldParams().beam_skip,
           "beam_skip_distance"_a = LikelihoodFieldParams().beam_skip_distance,
           "beam_skip_threshold"_a = LikelihoodFieldParams().beam_skip_threshold,
           "beam_skip_error_threshold"_a = LikelihoodFieldParams().beam_skip_error_threshold)
      .def("select_readings",
           [](LikelihoodFieldModel& lf, const py::handle& poses, int threads) {
             const auto a = as_doubles(poses, "poses");
             require_shape(a, "poses", 2, 3);
             std::vector<Pose2> p(static_cast<std::size_t>(a.shape(0)));
             for (std::size_t i = 0; i < p.size(); ++i) p[i] = pose_from_row(a.data() + 3 * i);
             py::gil_scoped_release release;
             lf.select_readings(p.data(), p.size(), threads);
           }, "poses"_a, "threads"_a = 1,
           "Beam skipping over these poses (n, 3); the engine's update() does it itself.")
      .def_property_readonly("used_beams", [](const LikelihoodFieldModel& lf) { return lf.used_beams(); })
      .def_property_readonly("beams", &LikelihoodFieldModel::beams)
      .def_property_readonly("outside", &LikelihoodFieldModel::outside,
                             "The term of an end off the map, for the current max range.")
      .def("set_scan",
           [](LikelihoodFieldModel& lf, const py::handle& a_in, const py::handle& r_in,
              double max_range) {
             const auto [a, r] = beams(a_in, r_in);
             lf.set_scan(a.data(), r.data(), static_cast<std::size_t>(a.shape(0)), max_range);
           }, "angles"_a, "ranges"_a, "max_range"_a)
      .def("table", [](const LikelihoodFieldModel& lf) { return mat_to_numpy(lf.table().clone()); },
           "The per-cell term (log pz, or pz^3 for nav2) for the current max range.");

  m.attr("BEAM_MODEL_CASTER") = BeamModelParams().caster;  // the default, held in C++ once
  py::class_<BeamModel, SensorModel>(m, "BeamModel")
      .def(py::init([](const OccupancyGrid& map, double z_hit, double z_short, double z_max,
                       double z_rand, double sigma, double lambda_short, int max_beams,
                       bool unknown_stops, BeamCombination combination, const Pose2& sensor,
                       double tolerance, RayCasterKind caster) {
             BeamModelParams p;
             p.caster = caster;
             p.z_hit = z_hit, p.z_short = z_short, p.z_max = z_max, p.z_rand = z_rand;
             p.sigma_hit = sigma, p.lambda_short = lambda_short, p.max_beams = max_beams;
             p.unknown_stops = unknown_stops, p.combination = combination, p.sensor = sensor;
             p.agreement_tolerance = tolerance;
             return std::make_unique<BeamModel>(map, p);
           }),
           "map"_a, "z_hit"_a = 0.5, "z_short"_a = 0.05, "z_max"_a = 0.05, "z_rand"_a = 0.5,
           "sigma_hit"_a = 0.2, "lambda_short"_a = 0.1, "max_beams"_a = 0,
           "unknown_stops"_a = true, "combination"_a = BeamCombination::product,
           "sensor"_a = Pose2(), "agreement_tolerance"_a = 0.2,
           "caster"_a = BeamModelParams().caster)
      .def("set_scan",
           [](BeamModel& bm, const py::handle& a_in, const py::handle& r_in, double max_range) {
             const auto [a, r] = beams(a_in, r_in);
             bm.set_scan(a.data(), r.data(), static_cast<std::size_t>(a.shape(0)), max_range);
           }, "angles"_a, "ranges"_a, "max_range"_a);

  py::class_<RaySpaceObservationModel, SensorModel>(m, "RaySpaceObservationModel")
      .def(py::init([](const OccupancyGrid& map, double sigma, double z_hit, double z_rand,
                       double z_intrusion, double lambda_short, double max_distance,
                       int max_beams, const Pose2& sensor, double tolerance, bool skips_intrusion) {
             RaySpaceObservationParams p;
             p.sigma_hit = sigma, p.z_hit = z_hit, p.z_rand = z_rand, p.z_intrusion = z_intrusion;
             p.lambda_short = lambda_short, p.max_distance = max_distance;
             p.max_beams = max_beams, p.sensor = sensor, p.agreement_tolerance = tolerance;
             p.agreement_skips_intrusion = skips_intrusion;
             return std::make_unique<RaySpaceObservationModel>(map, p);
           }),
           "map"_a, "sigma_hit"_a = 0.2, "z_hit"_a = 0.95, "z_rand"_a = 0.05,
           "z_intrusion"_a = 0.95, "lambda_short"_a = 0.1, "max_distance"_a = 2.0, "max_beams"_a = 0,
           "sensor"_a = Pose2(), "agreement_tolerance"_a = 0.2, "agreement_skips_intrusion"_a = false)
      .def("set_scan",
           [](RaySpaceObservationModel& model, const py::handle& a_in, const py::handle& r_in,
              double max_range) {
             const auto [a, r] = beams(a_in, r_in);
             model.set_scan(a.data(), r.data(), static_cast<std::size_t>(a.shape(0)), max_range);
           }, "angles"_a, "ranges"_a, "max_range"_a)
      .def("beam_probability", &RaySpaceObservationModel::beam_probability, "range"_a,
           "penetration"_a, "end_distance"_a,
           "pz of one beam from its reading, penetration depth and its end's distance to a wall.");

  py::class_<SpaceObservationModel, SensorModel>(m, "SpaceObservationModel")
      .def(py::init([](const OccupancyGrid& map, double sp, double si, double step, bool occ) {
             SpaceObservationParams p;
             p.sigma_penetration = sp;
             p.sigma_intrusion = si;
             p.heading_step_deg = step;
             p.occlusion_aware = occ;
             return std::make_unique<SpaceObservationModel>(map, p);
           }),
           "map"_a, "sigma_penetration"_a = 10.0, "sigma_intrusion"_a = 130.0,
           "heading_step_deg"_a = 1.0, "occlusion_aware"_a = false)
      .def("visible_from",
           [](const SpaceObservationModel& s, const Pose2& pose) { return s.visibility(pose); },
           "pose"_a, "Cells of the particle's window its cell sees (1) or not (0), int8.")
      .def("set_local_map", &SpaceObservationModel::set_local_map, "local_map"_a)
      .def("counts",
           [](const SpaceObservationModel& s, const Pose2& pose) {
             const auto c = s.counts(pose);
             return py::make_tuple(c.penetrating, c.map_occupied, c.intruding, c.map_free);
           }, "pose"_a, "(penetrating, map_occupied, intruding, map_free) in view")
      .def("likelihoods",
           [](const SpaceObservationModel& s, const py::handle& poses) {
             return per_pose(poses, [&](const double* p, std::size_t n, double* out) {
               s.likelihoods(p, n, out);
             });
           }, "poses"_a, "Likelihoods of particles (n, 3); releases the GIL.")
      .def("rotated_local_map", &SpaceObservationModel::rotated_local_map, "bin"_a)
      .def("bin_of", &SpaceObservationModel::bin_of, "heading"_a)
      .def_property_readonly("bins", &SpaceObservationModel::bins);
}

}  // namespace kiseki::bindings
