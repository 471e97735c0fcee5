// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/models/likelihood_field.hpp"

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <numeric>
#include <stdexcept>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/grid/distance_field.hpp"

namespace kiseki {

void LikelihoodFieldParams::validate() const {
  if (!(sigma_hit > 0.0) || !std::isfinite(sigma_hit) || !(z_hit >= 0.0) || !(z_rand >= 0.0) ||
      !(z_hit + z_rand > 0.0) || !std::isfinite(z_hit + z_rand)) {
    throw std::invalid_argument("likelihood field: need sigma_hit > 0, z_hit, z_rand >= 0 and not both 0");
  }
  // a micrometre at least: 1e-300 squared is 0, and the Gaussian 0 / 0 (NaN scores)
  if (sigma_hit < kMinSigmaHit) throw std::invalid_argument("likelihood field: sigma_hit must be at least 1e-6 m");
  if (max_beams < 0) throw std::invalid_argument("likelihood field: max_beams must be >= 0");
  if (!(max_distance > 0.0) || !std::isfinite(max_distance)) {
    throw std::invalid_argument("likelihood field: max_distance must be finite and > 0");
  }
  if (!(agreement_tolerance >= 0.0) || !std::isfinite(agreement_tolerance)) {
    throw std::invalid_argument("likelihood field: agreement_tolerance must be >= 0");
  }
  if (!(beam_skip_distance >= 0.0) || !std::isfinite(beam_skip_distance)) {
    throw std::invalid_argument("likelihood field: beam_skip_distance must be finite and >= 0");
  }
  if (!(beam_skip_threshold >= 0.0 && beam_skip_threshold <= 1.0) ||
      !(beam_skip_error_threshold >= 0.0 && beam_skip_error_threshold <= 1.0)) {
    throw std::invalid_argument("likelihood field: beam skip thresholds must lie in [0, 1]");
  }
}

namespace {

/// A robot pose's sensor in grid cells, (px, py), with its heading's cosine and sine: the value
/// of to_grid.compose(pose.compose(sensor)) (Pose2::compose, the same operations in the same
/// order, so the same bits), with the constant rotations' cos and sin taken once per call
/// instead of once per particle. A sensor at the robot's origin leaves its position as it is
/// (c * 0 - s * 0 adds a zero), so its rotation is not computed at all.
class SensorInGrid {
 public:
  SensorInGrid(const Pose2& origin, const Pose2& sensor, double resolution)
      : to_grid_(origin.inverse()),
        sensor_(sensor),
        at_origin_(sensor.x == 0.0 && sensor.y == 0.0),
        inv_res_(1.0 / resolution),
        cg_(std::cos(to_grid_.theta)),
        sg_(std::sin(to_grid_.theta)) {}

  void operator()(const Pose2& pose, double& px, double& py, double& c, double& sn) const {
    double x = pose.x, y = pose.y;
    if (!at_origin_) {
      const double cr = std::cos(pose.theta), sr = std::sin(pose.theta);
      x = pose.x + cr * sensor_.x - sr * sensor_.y;
      y = pose.y + sr * sensor_.x + cr * sensor_.y;
    }
    const double theta = normalize_angle(to_grid_.theta + normalize_angle(pose.theta + sensor_.theta));
    px = (to_grid_.x + cg_ * x - sg_ * y) * inv_res_;
    py = (to_grid_.y + sg_ * x + cg_ * y) * inv_res_;
    c = std::cos(theta);
    sn = std::sin(theta);
  }

 private:
  Pose2 to_grid_, sensor_;
  bool at_origin_;
  double inv_res_, cg_, sg_;
};

#if defined(__x86_64__) && defined(__GNUC__)
#define KISEKI_LIKELIHOOD_AVX2 1
/// The sums of the table's terms over the beams for P particles (placed at pose[j]: px, py, c,
/// sn), four beams at a time with AVX2 (chosen at run time): the end points are computed
/// with one IEEE operation per element, as the scalar loop computes them (no fused multiply-add:
/// only "avx2" is enabled), the four cells' terms gathered (the outside term where an end is
/// off the map), and added to each particle's sum one beam after the other, in beam order: the
/// scalar loop's bits. The P particles' sums are independent chains the processor overlaps: four
/// particles (then two for the rest) keep more of them in flight than two (3 % less time per
/// update at 10,000 particles and 60 beams, the same bits).
/// Needs width x height < 2^31 (32-bit cell indices).
template <int P>
__attribute__((target("avx2"))) void sums_avx2(const float* table, float outside, int w, int h,
                                               const double* bx, const double* by, std::size_t m,
                                               const double (*pose)[4], double* sums) {
  const __m256d zero = _mm256_setzero_pd(), width = _mm256_set1_pd(w), height = _mm256_set1_pd(h);
  const __m128i w4 = _mm_set1_epi32(w);
  const __m128 outside4 = _mm_set1_ps(outside);
  const __m256i low_halves = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
  __m256d px[P], py[P], c[P], sn[P];
  for (int j = 0; j < P; ++j) {
    px[j] = _mm256_set1_pd(pose[j][0]), py[j] = _mm256_set1_pd(pose[j][1]);
    c[j] = _mm256_set1_pd(pose[j][2]), sn[j] = _mm256_set1_pd(pose[j][3]);
  }
  double sum[P] = {};
  alignas(32) double terms[P][4];
  std::size_t b = 0;
  for (; b + 4 <= m; b += 4) {
    const __m256d ex = _mm256_loadu_pd(bx + b), ey = _mm256_loadu_pd(by + b);
    for (int j = 0; j < P; ++j) {
      const __m256d gx = _mm256_sub_pd(_mm256_add_pd(px[j], _mm256_mul_pd(c[j], ex)), _mm256_mul_pd(sn[j], ey));
      const __m256d gy = _mm256_add_pd(_mm256_add_pd(py[j], _mm256_mul_pd(sn[j], ex)), _mm256_mul_pd(c[j], ey));
      // gx >= 0 && gy >= 0 && gx < width && gy < height, false for NaN (ordered compares)
      const __m256d inside = _mm256_and_pd(
          _mm256_and_pd(_mm256_cmp_pd(gx, zero, _CMP_GE_OQ), _mm256_cmp_pd(gy, zero, _CMP_GE_OQ)),
          _mm256_and_pd(_mm256_cmp_pd(gx, width, _CMP_LT_OQ), _mm256_cmp_pd(gy, height, _CMP_LT_OQ)));
      const __m128 mask = _mm256_castps256_ps128(
          _mm256_castsi256_ps(_mm256_permutevar8x32_epi32(_mm256_castpd_si256(inside), low_halves)));
      // truncation (floor inside the grid); lanes off the map are masked out of the gather
      const __m128i cell = _mm_add_epi32(_mm_mullo_epi32(_mm256_cvttpd_epi32(gy), w4), _mm256_cvttpd_epi32(gx));
      const __m128 t = _mm_mask_i32gather_ps(outside4, table, cell, mask, 4);
      _mm256_store_pd(terms[j], _mm256_cvtps_pd(t));
    }
    for (int j = 0; j < P; ++j) {
      sum[j] += terms[j][0];
      sum[j] += terms[j][1];
      sum[j] += terms[j][2];
      sum[j] += terms[j][3];
    }
  }
  for (int j = 0; j < P; ++j) {  // the last beams one at a time, as the scalar loop
    for (std::size_t r = b; r < m; ++r) {
      const double gx = pose[j][0] + pose[j][2] * bx[r] - pose[j][3] * by[r];
      const double gy = pose[j][1] + pose[j][3] * bx[r] + pose[j][2] * by[r];
      const bool inside = gx >= 0.0 && gy >= 0.0 && gx < w && gy < h;
      sum[j] += inside ? table[static_cast<std::ptrdiff_t>(gy) * w + static_cast<std::ptrdiff_t>(gx)] : outside;
    }
    sums[j] = sum[j];
  }
}

bool has_avx2() {
  static const bool yes = (__builtin_cpu_init(), __builtin_cpu_supports("avx2"));
  return yes;
}
#endif

}  // namespace

LikelihoodFieldModel::LikelihoodFieldModel(const OccupancyGrid& map,
                                           const LikelihoodFieldParams& params)
    : params_((params.validate(), params)),
      frame_(map.clone()),
      distance_(distance_field(map)),
      occupied_(map, /*unknown_stops=*/false) {}

double LikelihoodFieldModel::term(double d, double max_range) const {
  const double s = params_.sigma_hit;
  const double g = std::exp(-d * d / (2.0 * s * s));
  const double rand = params_.z_rand / max_range;
  if (params_.combination == BeamCombination::nav2) {
    const double pz = params_.z_hit * g + rand;
    return pz * pz * pz;
  }
  return std::log(params_.z_hit * g / (std::sqrt(2.0 * kPi) * s) + rand);
}

void LikelihoodFieldModel::tabulate(double max_range) {
  if (max_range == table_range_) return;
  table_.create(distance_.rows, distance_.cols, CV_32FC1);
  for (int y = 0; y < distance_.rows; ++y) {
    const float* d = distance_.ptr<float>(y);
    float* t = table_.ptr<float>(y);
    for (int x = 0; x < distance_.cols; ++x) {
      t[x] = static_cast<float>(term(std::min<double>(d[x], params_.max_distance), max_range));
    }
  }
  outside_ = static_cast<float>(term(params_.max_distance, max_range));
  table_range_ = max_range;
}

void LikelihoodFieldModel::set_scan(const double* angles, const float* ranges, std::size_t n,
                                    double max_range) {
  beams_.set(angles, ranges, n, max_range, params_.max_beams, /*keep_no_return=*/false);
  tabulate(max_range);
  const double inv_res = 1.0 / frame_.resolution();
  end_x_.resize(beams_.size());
  end_y_.resize(beams_.size());
  for (std::size_t b = 0; b < beams_.size(); ++b) {
    end_x_[b] = beams_.range[b] * beams_.cos[b] * inv_res;
    end_y_[b] = beams_.range[b] * beams_.sin[b] * inv_res;
  }
  std::vector<std::size_t> all(beams_.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  use(std::move(all));
}

void LikelihoodFieldModel::use(std::vector<std::size_t> beams) {
  used_ = std::move(beams);
  used_x_.resize(used_.size());
  used_y_.resize(used_.size());
  for (std::size_t i = 0; i < used_.size(); ++i) used_x_[i] = end_x_[used_[i]], used_y_[i] = end_y_[used_[i]];
}

void LikelihoodFieldModel::select_readings(const Pose2* poses, std::size_t n, int threads) {
  if (!params_.beam_skip || n == 0) return;
  if (table_range_ < 0.0) throw std::logic_error("likelihood field: set a scan first");
  const std::size_t m = beams_.size();
  const SensorInGrid place(frame_.origin(), params_.sensor, frame_.resolution());
  const int w = frame_.width(), h = frame_.height();
  const float near = static_cast<float>(params_.beam_skip_distance);
  std::vector<std::size_t> near_wall(m, 0);  // per beam: particles whose end is near a wall
  std::mutex merge;
  parallel_for(n, threads, [&](std::size_t begin, std::size_t end) {
    std::vector<std::size_t> local(m, 0);
    for (std::size_t k = begin; k < end; ++k) {
      double px, py, c, sn;
      place(poses[k], px, py, c, sn);
      for (std::size_t b = 0; b < m; ++b) {
        const double gx = px + c * end_x_[b] - sn * end_y_[b], gy = py + sn * end_x_[b] + c * end_y_[b];
        if (gx >= 0.0 && gy >= 0.0 && gx < w && gy < h &&
            distance_.at<float>(static_cast<int>(gy), static_cast<int>(gx)) <= near) {
          ++local[b];
        }
      }
    }
    const std::lock_guard<std::mutex> lock(merge);  // integer sums: any order gives the same
    for (std::size_t b = 0; b < m; ++b) near_wall[b] += local[b];
  }, 256);
  std::vector<std::size_t> kept;
  const double needed = params_.beam_skip_threshold * static_cast<double>(n);
  for (std::size_t b = 0; b < m; ++b) {
    if (static_cast<double>(near_wall[b]) >= needed) kept.push_back(b);
  }
  const double skipped = static_cast<double>(m - kept.size());
  if (skipped > params_.beam_skip_error_threshold * static_cast<double>(m)) {
    kept.resize(m);
    std::iota(kept.begin(), kept.end(), std::size_t{0});
  }
  use(std::move(kept));
}

void LikelihoodFieldModel::log_likelihoods(const Pose2* poses, std::size_t n, double* out) const {
  if (table_range_ < 0.0) throw std::logic_error("likelihood field: set a scan first");
  // Everything in grid cells: a pose's sensor in the grid frame, then per beam one rotation.
  const SensorInGrid place(frame_.origin(), params_.sensor, frame_.resolution());
  const int w = frame_.width();
  const std::size_t m = used_.size();
  const double* bx = used_x_.data();
  const double* by = used_y_.data();
  const bool nav2 = params_.combination == BeamCombination::nav2;
  const float* table = table_.ptr<float>(0);  // continuous (created by tabulate)
  const float outside = outside_;
#if defined(__x86_64__)
  const auto uw = static_cast<std::uint64_t>(w), uh = static_cast<std::uint64_t>(frame_.height());
#else
  const double width = w, height = frame_.height();
#endif
  std::size_t k = 0;
#ifdef KISEKI_LIKELIHOOD_AVX2
  if (has_avx2() && static_cast<double>(w) * frame_.height() < 2147483648.0) {
    for (; k + 4 <= n; k += 4) {
      double p[4][4], sums[4];
      for (int j = 0; j < 4; ++j) place(poses[k + j], p[j][0], p[j][1], p[j][2], p[j][3]);
      sums_avx2<4>(table, outside, w, frame_.height(), bx, by, m, p, sums);
      for (int j = 0; j < 4; ++j) out[k + j] = nav2 ? std::log1p(sums[j]) : sums[j];
    }
    for (; k + 2 <= n; k += 2) {
      double p[2][4], sums[2];
      for (int j = 0; j < 2; ++j) place(poses[k + j], p[j][0], p[j][1], p[j][2], p[j][3]);
      sums_avx2<2>(table, outside, w, frame_.height(), bx, by, m, p, sums);
      for (int j = 0; j < 2; ++j) out[k + j] = nav2 ? std::log1p(sums[j]) : sums[j];
    }
  }
#endif
  for (; k < n; ++k) {
    double px, py, c, sn;
    place(poses[k], px, py, c, sn);
    double sum = 0.0;
    for (std::size_t b = 0; b < m; ++b) {
      const double gx = px + c * bx[b] - sn * by[b], gy = py + sn * bx[b] + c * by[b];
#if defined(__x86_64__)
      // The same test as below in fewer instructions: cvttsd2si truncates (floor for x >= 0),
      // and gives INT64_MIN, far above the grid as unsigned, for NaN and values out of range;
      // min(gx, gy) >= 0 is gx >= 0 && gy >= 0, NaN in gx fails it and NaN in gy fails iy.
      const std::int64_t ix = _mm_cvttsd_si64(_mm_set_sd(gx)), iy = _mm_cvttsd_si64(_mm_set_sd(gy));
      const bool inside = std::min(gx, gy) >= 0.0 && static_cast<std::uint64_t>(ix) < uw &&
                          static_cast<std::uint64_t>(iy) < uh;
      sum += inside ? table[iy * w + ix] : outside;
#else
      // Inside the grid the coordinates are >= 0, where truncation is floor.
      const bool inside = gx >= 0.0 && gy >= 0.0 && gx < width && gy < height;
      sum += inside ? table[static_cast<std::ptrdiff_t>(gy) * w + static_cast<std::ptrdiff_t>(gx)] : outside;
#endif
    }
    out[k] = nav2 ? std::log1p(sum) : sum;
  }
}

double LikelihoodFieldModel::agreement(const Pose2& pose) const {
  return beams_.agreement(occupied_, pose.compose(params_.sensor), params_.agreement_tolerance);
}

}  // namespace kiseki
