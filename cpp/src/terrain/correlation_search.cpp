// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/correlation_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>

#include "kiseki/core/parallel.hpp"

namespace kiseki {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kMaxCandidates = 1e8;

int axis_count(double low, double high, double step) {
  return static_cast<int>(std::floor((high - low) / step + 1e-9)) + 1;
}

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

/// The constants for projecting points onto the cells of one level: the fine grid's lower
/// edges (rad), its cells per rad and its extent in cells, and the level's block of
/// factor x factor fine cells.
struct Projection {
  float th_edge, ph_edge, inv, rows, cols;
  float inv_factor;  ///< 1 / factor
  int level_cols;
  float max_r2;
  int outside;  ///< the cell of points outside the grid or the range cut
};

/// Pass 1 of a candidate's score: each point's range and cell in the candidate's frame (eq. 3),
/// branch-free so that it vectorises; compiled for AVX2 and for the baseline, chosen at run time.
__attribute__((target_clones("avx2", "default"))) void project_points(const float* px, const float* py,
                                                                       const float* pz, std::size_t n, float cx,
                                                                       float cy, float cz, Projection g,
                                                                       int* __restrict cell_of,
                                                                       float* __restrict range_of) {
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

}  // namespace

void TranslationGrid::validate() const {
  for (const auto& [name, v] : {std::pair{"x_min", x_min}, {"x_max", x_max}, {"y_min", y_min}, {"y_max", y_max},
                                {"z_min", z_min}, {"z_max", z_max}, {"step", step}}) {
    if (!std::isfinite(v)) throw std::invalid_argument(std::string("search grid: ") + name + " must be finite");
  }
  if (!(step > 0)) {
    throw std::invalid_argument("search grid: step must be > 0 (a grid of zero steps), got " + std::to_string(step));
  }
  if (x_min > x_max || y_min > y_max || z_min > z_max) {
    throw std::invalid_argument("search grid: each axis needs min <= max");
  }
  const double n = (std::floor((x_max - x_min) / step) + 1) * (std::floor((y_max - y_min) / step) + 1) *
                   (std::floor((z_max - z_min) / step) + 1);
  if (n > kMaxCandidates) {
    throw std::invalid_argument("search grid: more than 10^8 candidates (" + std::to_string(n) + ")");
  }
}

int TranslationGrid::nx() const { return axis_count(x_min, x_max, step); }
int TranslationGrid::ny() const { return axis_count(y_min, y_max, step); }
int TranslationGrid::nz() const { return axis_count(z_min, z_max, step); }

Eigen::Vector3d TranslationGrid::at(std::size_t k) const {
  const std::size_t yz = static_cast<std::size_t>(ny()) * nz();
  const std::size_t ix = k / yz, iy = (k % yz) / nz(), iz = k % nz();
  return {x_min + ix * step, y_min + iy * step, z_min + iz * step};
}

void CorrelationOptions::validate() const {
  if (threads < 0) throw std::invalid_argument("correlation search: threads must be >= 0");
}

struct CorrelationSearch::Scratch {
  std::vector<float> zbuffer;  ///< the virtual map: nearest range per cell (+1 outside), +inf where empty
  std::vector<int> cell;       ///< each point's cell
  std::vector<float> range;
  std::vector<int> touched;    ///< the cells with a point, in the order of their first point
  explicit Scratch(std::size_t cells, std::size_t points)
      : zbuffer(cells + 1, kInf), cell(points), range(points), touched(points + 1) {}
};

CorrelationSearch::CorrelationSearch(const Eigen::Matrix3Xd& previous_points, const SphereElevationMap& current,
                                     const Eigen::Matrix3d& rotation, const CorrelationOptions& options)
    : grid_(current.grid()), options_(options), rotation_t_(rotation.transpose()) {
  options_.validate();
  if (!rotation.allFinite()) throw std::invalid_argument("correlation search: the attitude holds NaN or infinity");
  if (!(rotation.transpose() * rotation).isIdentity(1e-6) || rotation.determinant() < 0) {
    throw std::invalid_argument("correlation search: the attitude is not a rotation matrix");
  }
  if (previous_points.cols() == 0) throw std::invalid_argument("correlation search: the previous map has no points");
  if (!previous_points.allFinite()) {
    throw std::invalid_argument("correlation search: the previous points hold NaN or infinity");
  }
  if (current.valid_cells() == 0) throw std::invalid_argument("correlation search: the current S-DEM is empty");
  const Eigen::Matrix3Xd turned = rotation_t_ * previous_points;  // R^T p, so q = R^T p - R^T t
  const auto n = static_cast<std::size_t>(turned.cols());
  all_.x.resize(n);
  all_.y.resize(n);
  all_.z.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    all_.x[i] = static_cast<float>(turned(0, static_cast<Eigen::Index>(i)));
    all_.y[i] = static_cast<float>(turned(1, static_cast<Eigen::Index>(i)));
    all_.z[i] = static_cast<float>(turned(2, static_cast<Eigen::Index>(i)));
  }
  current_map_ = current.ranges();
  fine_ = make_level(1);
}

CorrelationSearch::Level CorrelationSearch::make_level(int factor) const {
  // Blocks of factor x factor fine cells; per block (and one extra for points outside): the
  // nearest range of the current map and eq. 4's weight cos(phi) at the block's centre, both 0
  // where the current map has no data. Factor 1 is the S-DEM itself.
  Level level;
  level.factor = factor;
  level.rows = (grid_.rows() + factor - 1) / factor;
  level.cols = (grid_.cols() + factor - 1) / factor;
  const std::size_t cells = static_cast<std::size_t>(level.rows) * level.cols;
  level.current.assign(cells + 1, 0.0f);
  level.weight.assign(cells + 1, 0.0f);
  for (int row = 0; row < grid_.rows(); ++row) {
    for (int col = 0; col < grid_.cols(); ++col) {
      const double r = current_map_[static_cast<std::size_t>(row) * grid_.cols() + col];
      if (std::isnan(r)) continue;
      const std::size_t block = static_cast<std::size_t>(row / factor) * level.cols + col / factor;
      const auto rf = static_cast<float>(r);
      level.current[block] = level.weight[block] > 0 ? std::min(level.current[block], rf) : rf;
      const double centre = grid_.phi_min_deg + ((col / factor) * factor + 0.5 * (factor - 1)) * grid_.step_deg;
      level.weight[block] = static_cast<float>(std::cos(std::min(90.0, std::abs(centre)) * kDeg));
      if (level.weight[block] <= 0) level.weight[block] = 1e-6f;  // a block on the pole keeps its data
    }
  }
  return level;
}

double CorrelationSearch::score(const Level& level, float cx, float cy, float cz, Scratch& s,
                                std::size_t* overlap) const {
  const Points& points = all_;
  const std::size_t n = points.x.size();
  const double half = 0.5 * grid_.step_deg;
  Projection g;
  g.th_edge = static_cast<float>((grid_.theta_min_deg - half) * kDeg);
  g.ph_edge = static_cast<float>((grid_.phi_min_deg - half) * kDeg);
  g.inv = static_cast<float>(1.0 / (grid_.step_deg * kDeg));
  g.rows = static_cast<float>(grid_.rows());
  g.cols = static_cast<float>(grid_.cols());
  g.inv_factor = 1.0f / static_cast<float>(level.factor);
  g.level_cols = level.cols;
  g.max_r2 = static_cast<float>(grid_.max_range * grid_.max_range);
  g.outside = level.rows * level.cols;
  project_points(points.x.data(), points.y.data(), points.z.data(), n, cx, cy, cz, g, s.cell.data(),
                 s.range.data());
  // Pass 2: the virtual S-DEM keeps the nearest point per cell; points outside the grid all
  // land in one extra cell that the current map never has data in. Branch-free: a cell enters
  // the touched list when its first point arrives.
  float* zbuffer = s.zbuffer.data();
  int* touched = s.touched.data();
  std::size_t touched_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int c = s.cell[i];
    float& slot = zbuffer[c];
    touched[touched_count] = c;
    touched_count += slot == kInf;
    slot = std::min(slot, s.range[i]);
  }
  // Eq. 4 over the cells with data in both maps (weight 0 where the current map has none).
  double sum = 0.0, weights = 0.0;
  std::size_t shared = 0;
  for (std::size_t k = 0; k < touched_count; ++k) {
    const auto cell = static_cast<std::size_t>(touched[k]);
    const double w = level.weight[cell];
    const double d = static_cast<double>(zbuffer[cell]) - level.current[cell];
    sum += d * d * w;
    weights += w;
    shared += w > 0.0;
    zbuffer[cell] = kInf;
  }
  if (overlap) *overlap = shared;
  // The overlap a coarse level needs: the fine one's over the cells of a block.
  const auto block = static_cast<std::size_t>(level.factor) * static_cast<std::size_t>(level.factor);
  const std::size_t need = std::max<std::size_t>(1, options_.min_overlap / block);
  if (shared < need) return std::numeric_limits<double>::infinity();
  return options_.cost == CorrelationCost::sum ? sum : sum / weights;
}

double CorrelationSearch::cost(const Eigen::Vector3d& translation, std::size_t* overlap) const {
  if (!translation.allFinite()) throw std::invalid_argument("correlation search: the translation holds NaN");
  Scratch scratch(grid_.cells(), points());
  const Eigen::Vector3d c = rotation_t_ * translation;
  return score(fine_, static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()), scratch, overlap);
}

namespace {

/// The best of scored candidates: lowest cost, ties to the lowest index.
template <typename Index>
std::size_t best_of(const std::vector<double>& costs, const std::vector<Index>& order) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < costs.size(); ++k) {
    if (costs[k] < costs[best] || (costs[k] == costs[best] && order[k] < order[best])) best = k;
  }
  return best;
}

}  // namespace

CorrelationResult CorrelationSearch::exhaustive(const TranslationGrid& grid) const {
  grid.validate();
  const std::size_t n = grid.size();
  CorrelationResult result;
  result.costs.assign(n, 0.0);
  std::vector<std::size_t> overlaps(n, 0);
  parallel_for(
      n, options_.threads,
      [&](std::size_t begin, std::size_t end) {
        Scratch scratch(grid_.cells(), points());
        for (std::size_t k = begin; k < end; ++k) {
          const Eigen::Vector3d c = rotation_t_ * grid.at(k);
          result.costs[k] = score(fine_, static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                                  scratch, &overlaps[k]);
        }
      },
      8);
  std::size_t best = 0;
  for (std::size_t k = 1; k < n; ++k) {
    if (result.costs[k] < result.costs[best]) best = k;
  }
  result.index = best;
  result.translation = grid.at(best);
  result.cost = result.costs[best];
  result.overlap = overlaps[best];
  result.evaluated = n;
  return result;
}

CorrelationResult CorrelationSearch::coarse_to_fine(const TranslationGrid& grid, int coarse, std::size_t keep) const {
  grid.validate();
  if (coarse < 1) throw std::invalid_argument("coarse-to-fine search: coarse must be >= 1");
  if (keep < 1) throw std::invalid_argument("coarse-to-fine search: keep must be >= 1");
  const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
  const auto index = [&](int ix, int iy, int iz) {
    return (static_cast<std::size_t>(ix) * ny + iy) * nz + iz;
  };
  // The lattice of one level: every `step`-th index along each axis, and the last index.
  const auto lattice = [](int count, int step) {
    std::vector<int> v;
    for (int i = 0; i < count; i += step) v.push_back(i);
    if (v.back() != count - 1) v.push_back(count - 1);
    return v;
  };
  std::vector<std::size_t> candidates;
  for (int ix : lattice(nx, coarse)) {
    for (int iy : lattice(ny, coarse)) {
      for (int iz : lattice(nz, coarse)) candidates.push_back(index(ix, iy, iz));
    }
  }
  CorrelationResult result;
  int step = coarse;
  while (true) {
    const Level coarse_level = step == 1 ? Level{} : make_level(step);
    const Level& used = step == 1 ? fine_ : coarse_level;
    std::vector<double> costs(candidates.size());
    std::vector<std::size_t> overlaps(candidates.size());
    parallel_for(
        candidates.size(), options_.threads,
        [&](std::size_t begin, std::size_t end) {
          Scratch scratch(grid_.cells(), points());
          for (std::size_t k = begin; k < end; ++k) {
            const Eigen::Vector3d c = rotation_t_ * grid.at(candidates[k]);
            costs[k] = score(used, static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                             scratch, &overlaps[k]);
          }
        },
        8);
    result.evaluated += candidates.size();
    if (step == 1) {
      const std::size_t best = best_of(costs, candidates);
      result.index = candidates[best];
      result.translation = grid.at(result.index);
      result.cost = costs[best];
      result.overlap = overlaps[best];
      return result;
    }
    // The `keep` best of this level, refined on the next level's lattice within one step.
    std::vector<std::size_t> order(candidates.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return costs[a] < costs[b] || (costs[a] == costs[b] && candidates[a] < candidates[b]);
    });
    const int next = std::max(1, step / 2);
    std::set<std::size_t> refined;
    for (std::size_t k = 0; k < std::min(keep, order.size()); ++k) {
      if (!std::isfinite(costs[order[k]])) break;
      const std::size_t c = candidates[order[k]];
      const int ix = static_cast<int>(c / (static_cast<std::size_t>(ny) * nz)), iy = static_cast<int>((c / nz) % ny),
                iz = static_cast<int>(c % nz);
      for (int dx = -step; dx <= step; dx += next) {
        for (int dy = -step; dy <= step; dy += next) {
          for (int dz = -step; dz <= step; dz += next) {
            const int x = ix + dx, y = iy + dy, z = iz + dz;
            if (x >= 0 && x < nx && y >= 0 && y < ny && z >= 0 && z < nz) refined.insert(index(x, y, z));
          }
        }
      }
    }
    if (refined.empty()) {  // nothing scored: every candidate overlaps too little
      result.index = candidates[order.front()];
      result.translation = grid.at(result.index);
      result.cost = std::numeric_limits<double>::infinity();
      return result;
    }
    candidates.assign(refined.begin(), refined.end());
    step = next;
  }
}

}  // namespace kiseki
