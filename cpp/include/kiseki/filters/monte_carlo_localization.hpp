// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "kiseki/core/pose.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/core/thread_chooser.hpp"
#include "kiseki/filters/kld_sampling.hpp"
#include "kiseki/filters/motion_model.hpp"
#include "kiseki/filters/resampling.hpp"
#include "kiseki/filters/sensor_reset_proposal.hpp"
#include "kiseki/grid/occupancy_grid.hpp"
#include "kiseki/models/sensor_model.hpp"

namespace kiseki {

/// What the filter does when the measurements stop agreeing with its particles.
enum class Recovery {
  none,
  /// Augmented MCL (Probabilistic Robotics, Table 8.3): short- and long-term averages of the
  /// per-reading likelihood, w_fast and w_slow; at each resampling a share max(0, 1 - w_fast /
  /// w_slow) of the new particles is drawn uniformly over the free cells (nav2's recovery).
  augmented,
  /// Expansion resetting (Ueda et al., emcl / emcl2) then sensor resetting (Lenser and Veloso,
  /// 2000). The cloud counts as lost on an update when the agreement of the measurement with
  /// the map seen from the particles (the model's agreement(), for scans emcl2's
  /// non-penetration share) is below reset_threshold, or, emcl2's other trigger, when the
  /// likelihood has dropped (w_fast / w_slow below reset_likelihood_drop): a cloud carried to a
  /// place that looks alike still mostly agrees with the map, but explains the scans worse than
  /// it used to. Where the model cannot tell (agreement NaN) the drop alone decides. After
  /// reset_after lost updates in a row every particle is moved by uniform noise
  /// (+-expansion_position, +-expansion_orientation) and weighed again; after
  /// sensor_reset_after, a share sensor_reset_share of the particles is drawn from
  /// sensor_reset_candidates uniform poses over the free cells in proportion to their
  /// likelihood (the measurement proposes where the robot can be) and the set is weighed
  /// again. Either reset is kept only if its best pose explains the measurement better than the
  /// cloud's best by a likelihood ratio of exp(reset_evidence): a cloud that is right but sees
  /// an odd scan is not scattered, nor one whose scans fit many places equally (open space).
  /// With resetting_injects, Augmented MCL's injection is added as well.
  resetting,
};
Recovery recovery_from_name(const std::string& name);

/// The longest odometry step, in metres, between two filter updates (and, as kiseki's log
/// readers apply it, between two consecutive scans): a longer one is a fault of the log (an
/// odometry reset, a corrupt value), not a motion. Over five times the largest step between
/// consecutive scans in the recorded logs kiseki reads (CSAIL's 1.78 m).
/// Python: kiseki._core.MAX_ODOMETRY_JUMP, kiseki.scans.MAX_ODOMETRY_JUMP.
inline constexpr double kMaxOdometryJump = 10.0;

struct MclParams {
  std::size_t particles = 1000;  ///< the count; with kld the maximum
  bool kld = false;              ///< adapt the count by KLD sampling at each resampling
  KldParams kld_params;          ///< (its max_particles is taken from `particles`)
  MotionParams motion;
  ResamplingMethod resampling = ResamplingMethod::systematic;
  double resample_threshold = 0.5;  ///< resample when ESS < threshold * n; >= 1: every update
  double likelihood_power = 1.0;    ///< log-likelihoods are multiplied by this (< 1 tempers)
  Recovery recovery = Recovery::none;
  double alpha_slow = 0.001, alpha_fast = 0.1;  ///< nav2's suggested recovery_alpha_*
  /// Whether resetting also injects uniform poses as Augmented MCL does. It catches a place
  /// that looks alike (a robot carried along a corridor), which the resets cannot see; but on
  /// real logs an injected pose that happens to fit one odd scan better than the whole cloud
  /// pulls the estimate away (ACES, Freiburg 079: RMSE 0.08 -> 2-7 m), so it is off by default.
  bool resetting_injects = false;
  double reset_threshold = 0.6;  ///< agreement below which the cloud counts as lost
  /// ... or w_fast / w_slow below this (the likelihood has dropped; the only test where the
  /// agreement is NaN); 0: agreement only, and never lost where the model cannot tell
  double reset_likelihood_drop = 0.5;
  /// A reset is kept only if its best pose beats the cloud's best by this log-likelihood ratio
  /// (tempered by likelihood_power): ln 10, a Bayes factor of 10 (Jeffreys' "strong").
  double reset_evidence = 2.302585092994046;
  /// ... and only if the map agrees with the measurement from the place it proposes (the
  /// weighted mean of its poses within 0.5 m and 0.3 rad of its best) at least as well as from
  /// the cloud's estimate, and at least reset_threshold (where the model can tell), both by the
  /// model's placement_agreement (its agreement but for the ray model's intrusion-tolerant one):
  /// a reset never moves the cloud to a place where, by that measure, it would count as lost, or
  /// to one that fits the map worse than where it is. Beams cut short by obstacles
  /// the map does not hold make the likelihood drop and fit a cluttered place elsewhere better
  /// than the truth under the likelihood field, but from there much of the scan passes through
  /// walls or ends in free space.
  bool reset_needs_agreement = true;
  double expansion_position = 0.2, expansion_orientation = 0.2;  ///< m, rad (half-widths)
  int reset_after = 2;         ///< disagreeing updates in a row before the first reset
  int sensor_reset_after = 4;  ///< ... before a sensor reset (expansions until then)
  double sensor_reset_share = 0.5;
  std::size_t sensor_reset_candidates = 20000;
  /// Where the sensor reset's candidates come from (the matcher needs set_matcher and the scan).
  ResetProposal sensor_reset_proposal = ResetProposal::uniform;
  /// With the matcher proposal, while the cloud stays lost the map is searched on every
  /// matcher_search_every-th sensor reset only; the resets between take their candidates around
  /// the last search's hypotheses, moved with the odometry. A search costs a fraction of a
  /// second to a second on a building's map, so a filter lost for good paid that on every
  /// update. The rule for 5: a place that a newer scan would propose waits at most 4 updates,
  /// a fifth of the 20 scans within which an excursion is to end. 1: a search on every sensor
  /// reset (kiseki before this option).
  int matcher_search_every = 5;
  /// Add ln N to reset_evidence for a sensor reset that took its best of N poses: N =
  /// sensor_reset_candidates (uniform) or the matcher's lattice poses (matcher). See
  /// look_elsewhere_term. Off: the acceptance of kiseki before the matcher proposal.
  bool reset_look_elsewhere = false;
  /// A sensor reset that passes its tests is held as a challenger, moved with the odometry,
  /// and made only if it passes them again on the next update's measurement: one scan that a
  /// place elsewhere explains better (people, clutter, a glass wall) must not move a cloud that
  /// is right, and two independent scans rarely both favour the same wrong place.
  bool sensor_reset_confirm = true;
  double reliability_rate = 0.1;       ///< smoothing of the reliability estimate per update
  /// 0 = every core, or one when one is measured faster over whole steps, motion and weighing
  /// (ThreadChooser: the results are the same for any thread count, so the choice changes only
  /// the time); n > 0: n threads.
  int threads = 0;
  void validate() const;
};

/// What one measurement update did.
struct UpdateReport {
  bool informative = false;        ///< the weights changed (some particle had a finite likelihood)
  double effective_sample_size = 0.0;  ///< after weighting, before resampling
  double average_likelihood = 0.0;  ///< weighted mean per-reading likelihood (Augmented MCL's w)
  double agreement = 0.0;           ///< of the measurement with the map (NaN: model cannot tell)
  bool resampled = false;
  std::size_t injected = 0;         ///< uniform poses added (Augmented MCL)
  std::string reset = "none";       ///< none, expansion or sensor
  bool searched = false;            ///< the matcher searched the map (matcher_search_every)
  std::size_t particles = 0;        ///< after the update
};

/// Monte Carlo localization on SE(2): one engine for every particle filter over planar poses in
/// kiseki (position tracking, global localization, the thesis' playback, magnetic models).
/// Particles and weights can be read and set. Every per-particle loop (motion, likelihood)
/// runs on `threads` threads; the random numbers of a particle come from its own stream, and
/// sums run in one fixed order, so one seed gives one trajectory for any thread count.
///
/// Reliability estimate: r <- r + rate (s - r) after each update, where s is 1 when the
/// measurement agrees with the map (agreement >= reset_threshold) and 0 when it does not; for
/// models that cannot tell, s = min(1, w_fast / w_slow). So r is the recent share of updates
/// that fit, and falls within a few updates when the filter is lost, where a confidence built
/// from the particles' spread alone stays high on a tight cloud in the wrong place.
class MonteCarloLocalization {
 public:
  MonteCarloLocalization(const MclParams& params, std::uint64_t seed);

  /// The free cells (value 0..19) that uniform poses are drawn from: the global start,
  /// Augmented MCL and sensor resetting need them. Throws if the map has no free cell.
  void set_free_space(const OccupancyGrid& map);
  bool has_free_space() const { return !free_cells_.empty(); }
  std::vector<Pose2> uniform_poses(std::size_t n);

  /// `particles` poses around a mean with the given SDs (m, m, rad); reliability 1.
  void initialize_gaussian(const Pose2& mean, double sd_x, double sd_y, double sd_theta);
  /// `particles` poses uniform over the free space; reliability 0.
  void initialize_uniform();
  /// Any n >= 1 poses, with weights (normalised here) or uniform weights when none are given.
  void set_particles(const std::vector<Pose2>& poses, const std::vector<double>& weights = {});
  /// New weights for the current particles (finite, >= 0, positive sum; normalised here).
  void set_weights(const std::vector<double>& weights);

  /// Moves the particles by an odometry increment. An increment longer than kMaxOdometryJump
  /// metres is refused (an odometry jump is a fault of the log, not a motion).
  void predict(const Pose2& odom_before, const Pose2& odom_after);
  /// Weighs the particles with a model that holds the current measurement, then recovers and
  /// resamples as configured. The model first chooses its readings from the cloud
  /// (SensorModel::select_readings, e.g. the likelihood field's beam skipping); a const model
  /// cannot, and is weighed with as it is.
  UpdateReport update(SensorModel& model);
  UpdateReport update(const SensorModel& model);
  /// The same, with the scan the model holds as the matcher reads it: a sensor reset with the
  /// matcher proposal searches it (the pointers are read during this call only).
  UpdateReport update(SensorModel& model, const ScanView& scan);
  UpdateReport update(const SensorModel& model, const ScanView& scan);
  /// The correlative scan matcher of the matcher proposal (not owned: it must outlive its use
  /// here; nullptr removes it). Its lattice cells should be the free cells set here.
  void set_matcher(const CorrelativeScanMatcher* matcher) { matcher_ = matcher; }
  /// The same with log-likelihoods computed elsewhere (one per particle), the number of
  /// readings they hold and their agreement (NaN if unknown). Resetting then expands without
  /// weighing again and never sensor-resets (that needs the model).
  UpdateReport update(const std::vector<double>& log_likelihoods, std::size_t readings, double agreement);
  /// Changes the likelihood power and the recovery between updates (global localization
  /// tempers the likelihood and recovers only once its cloud has converged). Throws on values
  /// MclParams::validate refuses. A new recovery starts Augmented MCL's averages afresh.
  void set_likelihood_power(double power);
  void set_recovery(Recovery recovery);
  /// Resamples now to n particles (e.g. a converged global cloud cut to the tracking size).
  void resample_to(std::size_t n);

  /// Weighted mean of the current particles (circular mean of the headings).
  Pose2 estimate() const;
  /// The weighted mean after the last update's weighing, before its resampling (so without
  /// the uniform poses Augmented MCL injects, which have no weight yet): the filter's answer.
  const Pose2& posterior() const { return posterior_; }
  /// Weighted covariance of (x, y, theta), the heading as its difference from the mean's.
  Eigen::Matrix3d covariance() const;
  double reliability() const { return reliability_; }
  double effective_sample_size() const;
  const std::vector<Pose2>& particles() const { return particles_; }
  /// The matcher's hypotheses of the current lost spell, moved with the odometry since its
  /// last search (empty when not lost or with the uniform proposal).
  const std::vector<PoseHypothesis>& matcher_hypotheses() const { return matcher_found_; }
  const std::vector<double>& weights() const { return weights_; }
  const MclParams& params() const { return params_; }

 private:
  /// The threads of this step: params_.threads, or the chooser's for 0.
  int threads_now() const { return params_.threads > 0 ? params_.threads : chooser_.threads(); }
  /// The updates with a model: `selects` (the model, or nullptr for a const one) chooses its
  /// readings from the cloud, then the cloud is weighed (the scan for the matcher proposal, or
  /// nullptr) and recovers; the time taken goes to the thread chooser.
  UpdateReport weigh(SensorModel* selects, const SensorModel& model, const ScanView* scan);
  /// Gives the thread chooser the step's time per particle: the motion updates since the last
  /// update and this update's `update_seconds`, for the `weighed` particles.
  void record_step(double update_seconds, std::size_t weighed);
  UpdateReport update_impl(const std::vector<double>& log_l, std::size_t readings, double agreement,
                           const SensorModel* model, const ScanView* scan);
  std::vector<double> evaluate(const SensorModel& model, const std::vector<Pose2>& poses) const;
  double agreement_of(const SensorModel& model, const Pose2& weighed) const;
  void resample(double inject_probability, UpdateReport& report);
  bool explains_better(double proposed_best, double cloud_best) const;
  /// What a reset must beat: the cloud's best log-likelihood and the placement agreement at
  /// its estimate (the model's placement_agreement, or the agreement given with log-likelihoods
  /// from elsewhere; NaN: it cannot tell).
  struct CloudScore {
    double best_log_likelihood;
    double placement_agreement;
  };
  bool agrees_at(const SensorModel& model, const std::vector<Pose2>& poses, const std::vector<double>& log_l,
                 const CloudScore& cloud) const;
  bool expansion_reset(const SensorModel* model, const CloudScore& cloud);
  bool sensor_reset(const SensorModel& model, const CloudScore& cloud, const ScanView* scan);
  /// The confirmation of a held sensor reset on this update's measurement (and its end).
  bool confirm_challenger(const SensorModel& model, const CloudScore& cloud);
  /// The particles a sensor reset draws from the proposed poses: sensor_reset_share of the cloud.
  std::size_t drawn_from_sensor() const;
  /// Replaces the cloud by its resampled part and the proposed poses drawn by their weights.
  void mix_in(const SensorModel& model, const std::vector<Pose2>& proposed, const std::vector<double>& log_l);
  std::vector<Pose2> reset_candidates(const ScanView* scan, double& searched);
  void check_ready() const;
  /// A lost spell ends (the cloud agrees again, a sensor reset is made, the recovery changes):
  /// its count, its held sensor reset and the matcher's places are dropped.
  void end_lost_spell();

  MclParams params_;
  Random rng_;
  std::vector<Pose2> particles_;
  std::vector<double> weights_;
  std::size_t target_ = 0;  // particle count without KLD
  // free space for uniform poses
  std::vector<std::int32_t> free_cells_;
  int free_width_ = 0;
  double free_resolution_ = 0.0;
  Pose2 free_origin_;
  // recovery state
  double w_slow_ = 0.0, w_fast_ = 0.0;
  int lost_updates_ = 0;
  std::vector<Pose2> challenger_;  // a sensor reset held for confirmation (sensor_reset_confirm)
  // the matcher's last hypotheses (moved with the odometry), its headings, and the sensor
  // resets that have drawn around them (matcher_search_every)
  std::vector<PoseHypothesis> matcher_found_;
  int matcher_headings_ = 0, matcher_uses_ = 0;
  bool searched_ = false;  // on this update
  double reliability_ = 1.0;
  Pose2 posterior_;
  const CorrelativeScanMatcher* matcher_ = nullptr;
  ThreadChooser chooser_;
  double predicted_seconds_ = 0.0;  // predict()'s time since the last update (the chooser's)
};

}  // namespace kiseki
