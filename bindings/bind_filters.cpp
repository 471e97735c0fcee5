// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <limits>
#include <optional>

#include "kiseki/filters/correlative_scan_matcher.hpp"
#include "kiseki/filters/kld_sampling.hpp"
#include "kiseki/filters/monte_carlo_localization.hpp"
#include "kiseki/filters/resampling.hpp"
#include "kiseki/filters/travel_distance_filter.hpp"
#include "numpy_helpers.hpp"

namespace kiseki::bindings {

using namespace pybind11::literals;

namespace {

std::vector<double> doubles_1d(const py::handle& in, const char* name) {
  const auto a = as_doubles(in, name);
  require_shape(a, name, 1);
  return std::vector<double>(a.data(), a.data() + a.shape(0));
}

std::vector<Pose2> poses_of(const py::handle& in) {
  const auto p = as_doubles(in, "poses");
  require_shape(p, "poses", 2, 3);
  std::vector<Pose2> out(static_cast<std::size_t>(p.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = pose_from_row(p.data() + 3 * i);
  return out;
}

py::array_t<double> poses_array(const std::vector<Pose2>& p) {
  py::array_t<double> out({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
  auto* d = out.mutable_data();
  for (std::size_t i = 0; i < p.size(); ++i) d[3 * i] = p[i].x, d[3 * i + 1] = p[i].y, d[3 * i + 2] = p[i].theta;
  return out;
}

py::array_t<double> array_of(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

}  // namespace

void bind_filters(py::module_& m) {
  m.def("resample_indices",
        [](const py::handle& w, std::size_t n, const std::string& method, std::uint64_t seed) {
          Random rng(seed);
          const auto idx = resample_indices(doubles_1d(w, "weights"), n, resampling_method_from_name(method), rng);
          py::array_t<std::int64_t> out(static_cast<py::ssize_t>(idx.size()));
          for (std::size_t i = 0; i < idx.size(); ++i) out.mutable_data()[i] = static_cast<std::int64_t>(idx[i]);
          return out;
        }, "weights"_a, "n"_a, "method"_a = "systematic", "seed"_a = 0,
        "n indices drawn from weights by multinomial, systematic, stratified or residual resampling.");
  m.def("kld_sample_bound", &kld_sample_bound, "bins"_a, "err"_a = 0.05, "z"_a = 0.99);
  m.def("effective_sample_size", [](const py::handle& w) { return effective_sample_size(doubles_1d(w, "weights")); },
        "weights"_a);

  py::class_<MclParams>(m, "MclParams", "Parameters of the Monte Carlo engine (see kiseki.localization.MclConfig).")
      .def(py::init<>())
      .def_readwrite("particles", &MclParams::particles)
      .def_readwrite("kld", &MclParams::kld)
      .def_property("kld_min_particles", [](const MclParams& p) { return p.kld_params.min_particles; },
                    [](MclParams& p, std::size_t v) { p.kld_params.min_particles = v; })
      .def_property("kld_err", [](const MclParams& p) { return p.kld_params.err; },
                    [](MclParams& p, double v) { p.kld_params.err = v; })
      .def_property("kld_z", [](const MclParams& p) { return p.kld_params.z; },
                    [](MclParams& p, double v) { p.kld_params.z = v; })
      .def_property("kld_bin_xy", [](const MclParams& p) { return p.kld_params.bin_xy; },
                    [](MclParams& p, double v) { p.kld_params.bin_xy = v; })
      .def_property("kld_bin_theta", [](const MclParams& p) { return p.kld_params.bin_theta; },
                    [](MclParams& p, double v) { p.kld_params.bin_theta = v; })
      .def_property("motion_model",
                    [](const MclParams& p) {
                      return std::string(p.motion.type == MotionModelType::differential ? "differential" : "omnidirectional");
                    },
                    [](MclParams& p, const std::string& v) { p.motion.type = motion_model_from_name(v); })
      .def_property("alphas",
                    [](const MclParams& p) {
                      return std::vector<double>{p.motion.alpha1, p.motion.alpha2, p.motion.alpha3, p.motion.alpha4, p.motion.alpha5};
                    },
                    [](MclParams& p, const std::vector<double>& a) {
                      if (a.size() != 4 && a.size() != 5) throw std::invalid_argument("alphas: give 4 (or 5, omnidirectional) values");
                      p.motion.alpha1 = a[0], p.motion.alpha2 = a[1], p.motion.alpha3 = a[2], p.motion.alpha4 = a[3];
                      if (a.size() == 5) p.motion.alpha5 = a[4];
                    })
      .def_property("resampling", [](const MclParams& p) { return std::string(resampling_method_name(p.resampling)); },
                    [](MclParams& p, const std::string& v) { p.resampling = resampling_method_from_name(v); })
      .def_readwrite("resample_threshold", &MclParams::resample_threshold)
      .def_readwrite("likelihood_power", &MclParams::likelihood_power)
      .def_property("recovery",
                    [](const MclParams& p) {
                      return std::string(p.recovery == Recovery::none ? "none" : p.recovery == Recovery::augmented ? "augmented" : "resetting");
                    },
                    [](MclParams& p, const std::string& v) { p.recovery = recovery_from_name(v); })
      .def_readwrite("alpha_slow", &MclParams::alpha_slow)
      .def_readwrite("alpha_fast", &MclParams::alpha_fast)
      .def_readwrite("resetting_injects", &MclParams::resetting_injects)
      .def_readwrite("reset_threshold", &MclParams::reset_threshold)
      .def_readwrite("reset_likelihood_drop", &MclParams::reset_likelihood_drop)
      .def_readwrite("reset_evidence", &MclParams::reset_evidence)
      .def_readwrite("reset_needs_agreement", &MclParams::reset_needs_agreement)
      .def_readwrite("sensor_reset_confirm", &MclParams::sensor_reset_confirm)
      .def_readwrite("expansion_position", &MclParams::expansion_position)
      .def_readwrite("expansion_orientation", &MclParams::expansion_orientation)
      .def_readwrite("reset_after", &MclParams::reset_after)
      .def_readwrite("sensor_reset_after", &MclParams::sensor_reset_after)
      .def_readwrite("sensor_reset_share", &MclParams::sensor_reset_share)
      .def_readwrite("sensor_reset_candidates", &MclParams::sensor_reset_candidates)
      .def_property("sensor_reset_proposal",
                    [](const MclParams& p) { return std::string(reset_proposal_name(p.sensor_reset_proposal)); },
                    [](MclParams& p, const std::string& v) { p.sensor_reset_proposal = reset_proposal_from_name(v); })
      .def_readwrite("matcher_search_every", &MclParams::matcher_search_every)
      .def_readwrite("reset_look_elsewhere", &MclParams::reset_look_elsewhere)
      .def_readwrite("reliability_rate", &MclParams::reliability_rate)
      .def_readwrite("threads", &MclParams::threads)
      .def("validate", &MclParams::validate);

  py::class_<UpdateReport>(m, "UpdateReport")
      .def_readonly("informative", &UpdateReport::informative)
      .def_readonly("effective_sample_size", &UpdateReport::effective_sample_size)
      .def_readonly("average_likelihood", &UpdateReport::average_likelihood)
      .def_readonly("agreement", &UpdateReport::agreement)
      .def_readonly("resampled", &UpdateReport::resampled)
      .def_readonly("injected", &UpdateReport::injected)
      .def_readonly("reset", &UpdateReport::reset)
      .def_readonly("searched", &UpdateReport::searched)
      .def_readonly("particles", &UpdateReport::particles);

  py::class_<MonteCarloLocalization>(m, "MonteCarloLocalization")
      .def(py::init<const MclParams&, std::uint64_t>(), "params"_a, "seed"_a = 0)
      .def("set_free_space", &MonteCarloLocalization::set_free_space, "map"_a)
      .def_property_readonly("has_free_space", &MonteCarloLocalization::has_free_space)
      .def("uniform_poses", [](MonteCarloLocalization& f, std::size_t n) { return poses_array(f.uniform_poses(n)); }, "n"_a)
      .def("initialize_gaussian", &MonteCarloLocalization::initialize_gaussian, "mean"_a, "sd_x"_a, "sd_y"_a, "sd_theta"_a)
      .def("initialize_uniform", &MonteCarloLocalization::initialize_uniform)
      .def("set_particles",
           [](MonteCarloLocalization& f, const py::handle& poses, const py::object& weights) {
             f.set_particles(poses_of(poses), weights.is_none() ? std::vector<double>{} : doubles_1d(weights, "weights"));
           }, "poses"_a, "weights"_a = py::none(),
           "Replaces the particles by poses (n, 3), with weights (normalised) or uniform weights.")
      .def("set_weights", [](MonteCarloLocalization& f, const py::handle& w) { f.set_weights(doubles_1d(w, "weights")); },
           "weights"_a)
      .def("predict", &MonteCarloLocalization::predict, "odom_before"_a, "odom_after"_a,
           py::call_guard<py::gil_scoped_release>())
      .def("update", [](MonteCarloLocalization& f, SensorModel& model) {
             py::gil_scoped_release release;
             return f.update(model);
           }, "model"_a, "Weighs with a model holding the current measurement; releases the GIL.")
      .def("update",
           [](MonteCarloLocalization& f, SensorModel& model, const py::handle& a_in, const py::handle& r_in) {
             const auto [a, r] = beams(a_in, r_in);
             py::gil_scoped_release release;
             return f.update(model, ScanView{a.data(), r.data(), static_cast<std::size_t>(a.shape(0))});
           }, "model"_a, "angles"_a, "ranges"_a,
           "The same with the scan the model holds (angles rad, ranges m, laser frame), which a sensor reset with "
           "the matcher proposal searches; releases the GIL.")
      .def("set_matcher", [](MonteCarloLocalization& f, const CorrelativeScanMatcher* m) { f.set_matcher(m); },
           "matcher"_a, py::keep_alive<1, 2>(),
           "The correlative scan matcher of the matcher proposal (None removes it).")
      .def("update_log_likelihoods",
           [](MonteCarloLocalization& f, const py::handle& log_l, std::size_t readings, double agreement) {
             auto l = doubles_1d(log_l, "log_likelihoods");
             py::gil_scoped_release release;
             return f.update(l, readings, agreement);
           }, "log_likelihoods"_a, "readings"_a = 1, "agreement"_a = std::numeric_limits<double>::quiet_NaN(),
           "Weighs with log-likelihoods computed elsewhere (a model written in Python), one per particle.")
      .def("resample_to", &MonteCarloLocalization::resample_to, "n"_a)
      .def("set_likelihood_power", &MonteCarloLocalization::set_likelihood_power, "power"_a)
      .def("set_recovery",
           [](MonteCarloLocalization& f, const std::string& r) { f.set_recovery(recovery_from_name(r)); },
           "recovery"_a)
      .def("estimate", &MonteCarloLocalization::estimate)
      .def("posterior", &MonteCarloLocalization::posterior,
           "The weighted mean after the last update's weighing, before its resampling.")
      .def("covariance", &MonteCarloLocalization::covariance)
      .def_property_readonly("reliability", &MonteCarloLocalization::reliability)
      .def_property_readonly("effective_sample_size", &MonteCarloLocalization::effective_sample_size)
      .def_property_readonly("poses", [](const MonteCarloLocalization& f) { return poses_array(f.particles()); })
      .def_property_readonly("matcher_hypotheses",
                             [](const MonteCarloLocalization& f) {
                               std::vector<Pose2> poses;
                               for (const PoseHypothesis& h : f.matcher_hypotheses()) poses.push_back(h.pose);
                               return poses_array(poses);
                             })
      .def_property_readonly("weights", [](const MonteCarloLocalization& f) { return array_of(f.weights()); })
      .def_property_readonly("size", [](const MonteCarloLocalization& f) { return f.particles().size(); });
  m.attr("MAX_ODOMETRY_JUMP") = kMaxOdometryJump;

  py::class_<SearchDisc>(m, "SearchDisc", "A disc that restricts a correlative search to one side of it.")
      .def(py::init([](double x, double y, double radius, bool inside) { return SearchDisc{x, y, radius, inside}; }),
           "x"_a, "y"_a, "radius"_a, "inside"_a = true)
      .def_readonly("x", &SearchDisc::x)
      .def_readonly("y", &SearchDisc::y)
      .def_readonly("radius", &SearchDisc::radius)
      .def_readonly("inside", &SearchDisc::inside);

  py::class_<CorrelativeScanMatcher>(m, "CorrelativeScanMatcher",
                                     "Global relocalization from one scan by branch-and-bound correlative matching.")
      .def(py::init([](const OccupancyGrid& map, double max_range, double sigma, double z_hit, double z_rand,
                       int max_beams, double max_distance, const Pose2& sensor, int depth, double angular_step,
                       int hypotheses, double min_distance, double min_angle, bool free_only, int threads) {
             CorrelativeMatcherParams p;
             auto& l = p.likelihood;
             l.sigma_hit = sigma, l.z_hit = z_hit, l.z_rand = z_rand, l.max_beams = max_beams;
             l.max_distance = max_distance, l.sensor = sensor;
             p.depth = depth, p.angular_step = angular_step, p.hypotheses = hypotheses;
             p.min_distance = min_distance, p.min_angle = min_angle, p.free_only = free_only, p.threads = threads;
             py::gil_scoped_release release;
             return std::make_unique<CorrelativeScanMatcher>(map, max_range, p);
           }),
           "map"_a, "max_range"_a, "sigma_hit"_a, "z_hit"_a, "z_rand"_a, "max_beams"_a, "max_distance"_a,
           "sensor"_a, "depth"_a, "angular_step"_a, "hypotheses"_a, "min_distance"_a, "min_angle"_a, "free_only"_a,
           "threads"_a)
      .def("match",
           [](const CorrelativeScanMatcher& cm, const py::handle& a_in, const py::handle& r_in,
              std::optional<SearchDisc> disc) {
             const auto [a, r] = beams(a_in, r_in);
             std::vector<PoseHypothesis> found;
             {
               py::gil_scoped_release release;
               found = cm.match(a.data(), r.data(), static_cast<std::size_t>(a.shape(0)), disc ? &*disc : nullptr);
             }
             const auto k = static_cast<py::ssize_t>(found.size());
             py::array_t<double> poses({k, py::ssize_t{3}}), scores(k);
             py::array_t<std::int64_t> lattice({k, py::ssize_t{3}});
             for (py::ssize_t i = 0; i < k; ++i) {
               const auto& h = found[static_cast<std::size_t>(i)];
               poses.mutable_at(i, 0) = h.pose.x, poses.mutable_at(i, 1) = h.pose.y, poses.mutable_at(i, 2) = h.pose.theta;
               scores.mutable_at(i) = h.score;
               lattice.mutable_at(i, 0) = h.cell_x, lattice.mutable_at(i, 1) = h.cell_y, lattice.mutable_at(i, 2) = h.heading;
             }
             return py::make_tuple(poses, scores, lattice);
           }, "angles"_a, "ranges"_a, "disc"_a = py::none(),
           "(poses (k, 3), scores (k,), lattice (k, 3): cell x, cell y, heading index), best first, over the poses on "
           "the disc's side when one is given; releases the GIL.")
      .def("headings",
           [](const CorrelativeScanMatcher& cm, const py::handle& a_in, const py::handle& r_in) {
             const auto [a, r] = beams(a_in, r_in);
             return cm.headings(a.data(), r.data(), static_cast<std::size_t>(a.shape(0)));
           }, "angles"_a, "ranges"_a, "Headings on the search lattice for this scan.")
      .def("lattice_pose", &CorrelativeScanMatcher::lattice_pose, "cell_x"_a, "cell_y"_a, "heading"_a, "headings"_a);

  py::class_<TravelDistanceParams>(m, "TravelDistanceParams")
      .def(py::init<>())
      .def_readwrite("particles", &TravelDistanceParams::particles)
      .def_readwrite("kld", &TravelDistanceParams::kld)
      .def_property("kld_min_particles", [](const TravelDistanceParams& p) { return p.kld_params.min_particles; },
                    [](TravelDistanceParams& p, std::size_t v) { p.kld_params.min_particles = v; })
      .def_property("kld_bin", [](const TravelDistanceParams& p) { return p.kld_params.bin_distance; },
                    [](TravelDistanceParams& p, double v) { p.kld_params.bin_distance = v; })
      .def_property("resampling", [](const TravelDistanceParams& p) { return std::string(resampling_method_name(p.resampling)); },
                    [](TravelDistanceParams& p, const std::string& v) { p.resampling = resampling_method_from_name(v); })
      .def_readwrite("resample_threshold", &TravelDistanceParams::resample_threshold)
      .def_readwrite("likelihood_power", &TravelDistanceParams::likelihood_power)
      .def_readwrite("threads", &TravelDistanceParams::threads);

  py::class_<TravelDistanceFilter>(m, "TravelDistanceFilter")
      .def(py::init<const TravelDistanceParams&, std::uint64_t>(), "params"_a, "seed"_a = 0)
      .def("initialize", &TravelDistanceFilter::initialize, "mean"_a, "sd"_a)
      .def("set_particles",
           [](TravelDistanceFilter& f, const py::handle& d, const py::object& w) {
             f.set_particles(doubles_1d(d, "distances"), w.is_none() ? std::vector<double>{} : doubles_1d(w, "weights"));
           }, "distances"_a, "weights"_a = py::none())
      .def("set_weights", [](TravelDistanceFilter& f, const py::handle& w) { f.set_weights(doubles_1d(w, "weights")); }, "weights"_a)
      .def("predict", &TravelDistanceFilter::predict, "distance"_a, "sd"_a, py::call_guard<py::gil_scoped_release>())
      .def("set_scales", [](TravelDistanceFilter& f, const py::handle& k) { f.set_scales(doubles_1d(k, "scales")); }, "scales"_a)
      .def("predict_scaled", &TravelDistanceFilter::predict_scaled, "distance"_a, "sd"_a, "scale_sd"_a,
           py::call_guard<py::gil_scoped_release>())
      .def("update", [](TravelDistanceFilter& f, const py::handle& l) { return f.update(doubles_1d(l, "log_likelihoods")); },
           "log_likelihoods"_a)
      .def("estimate", &TravelDistanceFilter::estimate)
      .def("variance", &TravelDistanceFilter::variance)
      .def_property_readonly("effective_sample_size", &TravelDistanceFilter::effective_sample_size)
      .def_property_readonly("particles", [](const TravelDistanceFilter& f) { return array_of(f.particles()); })
      .def_property_readonly("weights", [](const TravelDistanceFilter& f) { return array_of(f.weights()); })
      .def_property_readonly("scales", [](const TravelDistanceFilter& f) { return array_of(f.scales()); });
}

}  // namespace kiseki::bindings
