// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/virtual_sdem.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "kiseki/core/angle.hpp"

namespace kiseki {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Four doubles, floats and ints: GCC's and Clang's vector types, so that eq. 4's sums are
/// vectorised in a fixed order (slot j adds to lane j % 8 of two such halves, the lanes are added
/// last). Four, not eight, in a type: eight doubles are wider than an AVX2 register, and GCC then
/// kept the sums on the stack, reloading them every step.
using Double4 = double __attribute__((vector_size(32)));
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int __attribute__((vector_size(16)));

/// Lanes 0..3 or 4..7 of eq. 4's sums: four slots' terms added to them, the slots reset to +inf.
struct Eq4Lanes {
  Double4 sum = {}, weights = {};
  Int4 shared = {};
  inline void add(float* __restrict zbuffer, const float* __restrict current, const float* __restrict weight) {
    const Float4 empty = {kInf, kInf, kInf, kInf};
    const Float4 far = {1e30f, 1e30f, 1e30f, 1e30f};
    const Float4 none = {};
    Float4 nearest, c, v;
    std::memcpy(&nearest, zbuffer, sizeof nearest);
    std::memcpy(&c, current, sizeof c);
    std::memcpy(&v, weight, sizeof v);
    std::memcpy(zbuffer, &empty, sizeof empty);
    const Int4 hit = nearest < empty;  // all ones where a point landed
    const Float4 range = far < nearest ? far : nearest;
    const Double4 w = __builtin_convertvector(hit ? v : none, Double4);
    const Double4 d = __builtin_convertvector(range, Double4) - __builtin_convertvector(c, Double4);
    sum += d * d * w;
    weights += w;
    shared -= hit;
  }
};

/// atan(t) for |t| <= 1: an odd polynomial of degree 15 fitted for the least maximum error
/// (4e-8 rad; in float arithmetic 1.4e-7 rad, the rounding of the result itself).
inline float atan_unit(float t) {
  const float t2 = t * t;
  float p = -4.054586057e-03f;
  p = p * t2 + 2.186301495e-02f;
  p = p * t2 - 5.591239031e-02f;
  p = p * t2 + 9.642200350e-02f;
  p = p * t2 - 1.390862997e-01f;
  p = p * t2 + 1.994656555e-01f;
  p = p * t2 - 3.332986076e-01f;
  p = p * t2 + 9.999993356e-01f;
  return t * p;
}

/// atan2 on the unit polynomial, branch-free so that the compiler can vectorise the loop.
inline float fast_atan2(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  const float a = atan_unit(lo / std::max(hi, 1e-30f));
  float r = ay > ax ? static_cast<float>(M_PI_2) - a : a;
  r = x < 0.0f ? static_cast<float>(M_PI) - r : r;
  return y < 0.0f ? -r : r;
}

/// An upper bound of asin(s) for 0 <= s < 1: tan(asin(s)) = s / sqrt(1 - s^2) >= asin(s).
inline float asin_bound(float s) { return s / std::sqrt(std::max(1.0f - s * s, 1e-12f)); }

/// The widened cell rectangle of each point (rows lo..hi, columns lo..hi; lo > hi: none), as in
/// points_that_may_land. The margins (1e-4 rad) cover the float arctangent's error many times.
__attribute__((target_clones("avx512f", "avx2", "default"))) void widened_cells(
    const float* px, const float* py, const float* pz, std::size_t n, float cx, float cy, float cz, float rho,
    CellProjection g, float max_range, int* __restrict row_lo, int* __restrict row_hi, int* __restrict col_lo,
    int* __restrict col_hi) {
  constexpr float kMargin = 1e-4f, kPiF = static_cast<float>(kPi);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = px[i] - cx, y = py[i] - cy, z = pz[i] - cz;
    const float h2 = x * x + z * z, r = std::sqrt(h2 + y * y), h = std::sqrt(h2);
    const float th = fast_atan2(z, x), ph = fast_atan2(y, h);
    const float s_r = rho / std::max(r, 1e-30f), s_h = rho / std::max(h, 1e-30f);
    const float d_ph = asin_bound(std::min(s_r, 0.5f)) + kMargin;
    const float d_th = asin_bound(std::min(s_h, 0.5f)) + kMargin;
    const bool any_ph = s_r >= 0.5f;  // too near: any direction
    const bool any_th = (s_h >= 0.5f) | (th - d_th < -kPiF) | (th + d_th > kPiF);
    const bool far = r - rho >= max_range;
    const float r_lo = any_th ? 0.0f : (th - d_th - g.th_edge) * g.inv;
    const float r_hi = any_th ? g.rows : (th + d_th - g.th_edge) * g.inv;
    const float c_lo = any_ph ? 0.0f : (ph - d_ph - g.ph_edge) * g.inv;
    const float c_hi = any_ph ? g.cols : (ph + d_ph - g.ph_edge) * g.inv;
    // truncation rounds a negative upper end up to 0: one row or column more, still a bound
    row_lo[i] = far ? 1 : static_cast<int>(std::min(std::max(r_lo, 0.0f), g.rows));
    row_hi[i] = far ? 0 : static_cast<int>(std::min(std::max(r_hi, -1.0f), g.rows - 1.0f));
    col_lo[i] = static_cast<int>(std::min(std::max(c_lo, 0.0f), g.cols));
    col_hi[i] = static_cast<int>(std::min(std::max(c_hi, -1.0f), g.cols - 1.0f));
  }
}

}  // namespace

CellProjection::CellProjection(const SphereGrid& grid, int factor, int level_rows, int level_cols_)
    : level_cols(level_cols_) {
  const double half = 0.5 * grid.step_deg;
  th_edge = static_cast<float>((grid.theta_min_deg - half) * kDegree);
  ph_edge = static_cast<float>((grid.phi_min_deg - half) * kDegree);
  inv = static_cast<float>(1.0 / (grid.step_deg * kDegree));
  rows = static_cast<float>(grid.rows());
  cols = static_cast<float>(grid.cols());
  inv_factor = 1.0f / static_cast<float>(factor);
  max_r2 = static_cast<float>(grid.max_range * grid.max_range);
  outside = level_rows * level_cols_;
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void project_points(
    const float* px, const float* py, const float* pz, std::size_t n, float cx, float cy, float cz,
    const CellProjection& projection, int* __restrict cell_of, float* __restrict range_of) {
  const CellProjection g = projection;
  for (std::size_t i = 0; i < n; ++i) {
    const float x = px[i] - cx, y = py[i] - cy, z = pz[i] - cz;
    const float xz2 = x * x + z * z, r2 = xz2 + y * y;
    const float vr = (fast_atan2(z, x) - g.th_edge) * g.inv;  // fine cells from the lower edge
    const float vc = (fast_atan2(y, std::sqrt(xz2)) - g.ph_edge) * g.inv;
    const bool inside =
        (r2 > 0.0f) & (r2 < g.max_r2) & (vr >= 0.0f) & (vr < g.rows) & (vc >= 0.0f) & (vc < g.cols);
    const int row = static_cast<int>(std::min(std::max(vr, 0.0f), g.rows - 1.0f) * g.inv_factor);
    const int col = static_cast<int>(std::min(std::max(vc, 0.0f), g.cols - 1.0f) * g.inv_factor);
    cell_of[i] = inside ? row * g.level_cols + col : g.outside;
    range_of[i] = std::sqrt(r2);
  }
}

std::size_t points_that_may_land(const float* px, const float* py, const float* pz, std::size_t n, double cx,
                                 double cy, double cz, double rho, const SphereGrid& grid,
                                 const std::vector<int>& data_sat, std::vector<int>& scratch,
                                 std::uint32_t* kept) {
  scratch.resize(4 * n);
  int* row_lo = scratch.data();
  int *row_hi = row_lo + n, *col_lo = row_hi + n, *col_hi = col_lo + n;
  const CellProjection g(grid, 1, grid.rows(), grid.cols());
  // 1e-5 m more for the float rounding of the candidates' centres
  widened_cells(px, py, pz, n, static_cast<float>(cx), static_cast<float>(cy), static_cast<float>(cz),
                static_cast<float>(rho + 1e-5), g, static_cast<float>(grid.max_range), row_lo, row_hi, col_lo,
                col_hi);
  const auto stride = static_cast<std::size_t>(grid.cols()) + 1;
  const auto at = [&](int row, int col) {
    return data_sat[static_cast<std::size_t>(row) * stride + static_cast<std::size_t>(col)];
  };
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (row_lo[i] > row_hi[i] || col_lo[i] > col_hi[i]) continue;
    const int r0 = row_lo[i], r1 = row_hi[i] + 1, c0 = col_lo[i], c1 = col_hi[i] + 1;
    if (at(r1, c1) - at(r0, c1) - at(r1, c0) + at(r0, c0) > 0) kept[count++] = static_cast<std::uint32_t>(i);
  }
  return count;
}

__attribute__((target_clones("avx512f", "avx2", "default"))) Eq4Sums eq4_sums(float* __restrict zbuffer,
                                                                                const float* __restrict current,
                                                                                const float* __restrict weight,
                                                                                std::size_t slots) {
  // One pass over the slots, eight at a time: slot j adds to lane j % 8 of the sums. An empty
  // slot (+inf) has weight 0 and a finite stand-in range, so its term (finite)^2 * 0 is 0.
  Eq4Lanes low, high;
  for (std::size_t j = 0; j < slots; j += 8) {
    low.add(zbuffer + j, current + j, weight + j);
    high.add(zbuffer + j + 4, current + j + 4, weight + j + 4);
  }
  Eq4Sums t;
  for (const Eq4Lanes* half : {&low, &high}) {
    for (int l = 0; l < 4; ++l) {
      t.sum += half->sum[l];
      t.weights += half->weights[l];
      t.shared += static_cast<std::size_t>(half->shared[l]);
    }
  }
  return t;
}

}  // namespace kiseki
