// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/terrain/correlation_search.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/parallel.hpp"
#include "kiseki/terrain/virtual_sdem.hpp"

namespace kiseki {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kMaxCandidates = 1e8;

int axis_count(double low, double high, double step) {
  return static_cast<int>(std::floor((high - low) / step + 1e-9)) + 1;
}

/// Slots after the data cells' for the points that land elsewhere (outside, or in a cell
/// without data): they hold -inf, so such a point never enters eq. 4.
constexpr int kDummySlots = 8;
/// Candidates per side of the blocks that the exhaustive search leaves points out for.
constexpr int kBlock = 4;

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
  check_threads(threads, "correlation search");
}

struct CorrelationSearch::Scratch {
  /// The virtual map: the nearest range per slot of a cell with data, +inf where empty,
  /// then the dummy slots at -inf.
  std::vector<float> zbuffer;
  std::vector<int> cell;     ///< each point's cell
  std::vector<float> range_of;  ///< each point's range
  std::vector<std::uint32_t> kept;  ///< the points that may land in a cell with data (exhaustive)
  std::vector<float> x, y, z;       ///< those points
  std::vector<int> bounds;
  Scratch(std::size_t slots, std::size_t points)
      : zbuffer(slots + kDummySlots, kInf), cell(points), range_of(points), kept(points),
        x(points), y(points), z(points) {
    std::fill(zbuffer.begin() + static_cast<std::ptrdiff_t>(slots), zbuffer.end(), -kInf);
  }
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
  // Blocks of factor x factor fine cells; per block with data, in block order: the nearest
  // range of the current map and eq. 4's weight cos(phi) at the block's centre. Factor 1 is the
  // S-DEM itself.
  Level level;
  level.factor = factor;
  level.rows = (grid_.rows() + factor - 1) / factor;
  level.cols = (grid_.cols() + factor - 1) / factor;
  const std::size_t blocks = static_cast<std::size_t>(level.rows) * level.cols;
  std::vector<float> current(blocks, kInf), weight(blocks, 0.0f);
  for (int row = 0; row < grid_.rows(); ++row) {
    for (int col = 0; col < grid_.cols(); ++col) {
      const double r = current_map_[static_cast<std::size_t>(row) * grid_.cols() + col];
      if (std::isnan(r)) continue;
      const std::size_t block = static_cast<std::size_t>(row / factor) * level.cols + col / factor;
      current[block] = std::min(current[block], static_cast<float>(r));
      const double centre = grid_.phi_min_deg + ((col / factor) * factor + 0.5 * (factor - 1)) * grid_.step_deg;
      weight[block] = static_cast<float>(std::cos(std::min(90.0, std::abs(centre)) * kDegree));
      if (weight[block] <= 0) weight[block] = 1e-6f;  // a block on the pole keeps its data
    }
  }
  level.slot.assign(blocks + 1, -1);  // the last: points outside the grid
  for (std::size_t block = 0; block < blocks; ++block) {
    if (weight[block] == 0.0f) continue;
    level.slot[block] = static_cast<int>(level.current.size());
    level.current.push_back(current[block]);
    level.weight.push_back(weight[block]);
  }
  while (level.current.size() % 8) {  // padding: never a point's slot, weight 0
    level.current.push_back(0.0f);
    level.weight.push_back(0.0f);
  }
  // The summed-area table of the fine cells whose block has data.
  const auto stride = static_cast<std::size_t>(grid_.cols()) + 1;
  level.data_sat.assign((static_cast<std::size_t>(grid_.rows()) + 1) * stride, 0);
  for (int row = 0; row < grid_.rows(); ++row) {
    for (int col = 0; col < grid_.cols(); ++col) {
      const std::size_t block = static_cast<std::size_t>(row / factor) * level.cols + col / factor;
      const std::size_t at = static_cast<std::size_t>(row + 1) * stride + col + 1;
      level.data_sat[at] = (level.slot[block] >= 0) + level.data_sat[at - 1] + level.data_sat[at - stride] -
                           level.data_sat[at - stride - 1];
    }
  }
  return level;
}

double CorrelationSearch::score(const Level& level, float cx, float cy, float cz, Scratch& s,
                                std::size_t* overlap, const float* px, const float* py, const float* pz,
                                std::size_t n) const {
  // Pass 1: each point's cell and range in the candidate's frame (eq. 3).
  project_points(px, py, pz, n, cx, cy, cz, CellProjection(grid_, level.factor, level.rows, level.cols),
                 s.cell.data(), s.range_of.data());
  // Pass 2: the virtual S-DEM keeps the nearest point per cell with data; the other points land
  // in the dummy slots, in turn so that consecutive points do not wait on one another's store.
  const int* slot_of = level.slot.data();
  const int dummy = static_cast<int>(level.current.size());
  float* zbuffer = s.zbuffer.data();
  for (std::size_t i = 0; i < n; ++i) {
    const int found = slot_of[s.cell[i]];
    const int elsewhere = found >> 31;  // all ones where the cell has no data (found = -1)
    const int slot = (found & ~elsewhere) | ((dummy + static_cast<int>(i % kDummySlots)) & elsewhere);
    float& nearest = zbuffer[slot];
    nearest = std::min(nearest, s.range_of[i]);
  }
  // Eq. 4 over the cells with data in both maps, in the slots' (the cells') order.
  const Eq4Sums terms = eq4_sums(zbuffer, level.current.data(), level.weight.data(), level.current.size());
  const double sum = terms.sum, weights = terms.weights;
  const std::size_t shared = terms.shared;
  if (overlap) *overlap = shared;
  // The overlap a coarse level needs: the fine one's over the cells of a block.
  const auto block = static_cast<std::size_t>(level.factor) * static_cast<std::size_t>(level.factor);
  const std::size_t need = std::max<std::size_t>(1, options_.min_overlap / block);
  if (shared < need) return std::numeric_limits<double>::infinity();
  return options_.cost == CorrelationCost::sum ? sum : sum / weights;
}

double CorrelationSearch::score(const Level& level, const Eigen::Vector3d& translation, Scratch& s,
                                std::size_t* overlap) const {
  const Eigen::Vector3d c = rotation_t_ * translation;
  return score(level, static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()), s, overlap,
               all_.x.data(), all_.y.data(), all_.z.data(), points());
}

double CorrelationSearch::cost(const Eigen::Vector3d& translation, std::size_t* overlap) const {
  if (!translation.allFinite()) throw std::invalid_argument("correlation search: the translation holds NaN");
  Scratch scratch(fine_.current.size(), points());
  return score(fine_, translation, scratch, overlap);
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
  // Blocks of kBlock^3 neighbouring candidates: the points that cannot land in a cell with
  // data from any candidate of a block are left out of its scores, which they would not change.
  const int nx = grid.nx(), ny = grid.ny(), nz = grid.nz();
  const int bx = (nx + kBlock - 1) / kBlock, by = (ny + kBlock - 1) / kBlock, bz = (nz + kBlock - 1) / kBlock;
  // One block after another to whichever thread is free (the blocks' work differs with the
  // points they keep); each writes only its own candidates, so the result is the same.
  const auto blocks = static_cast<long long>(bx) * by * bz;
  std::exception_ptr error;
#pragma omp parallel num_threads(std::min(resolve_threads(options_.threads), kMaxThreads))
  {
    try {
      Scratch s(fine_.current.size(), points());
#pragma omp for schedule(dynamic, 1)
      for (long long block = 0; block < blocks; ++block) {
        const auto b = static_cast<std::size_t>(block);
        const int x0 = static_cast<int>(b / (static_cast<std::size_t>(by) * bz)) * kBlock;
        const int y0 = static_cast<int>((b / bz) % by) * kBlock, z0 = static_cast<int>(b % bz) * kBlock;
        const int x1 = std::min(nx, x0 + kBlock), y1 = std::min(ny, y0 + kBlock), z1 = std::min(nz, z0 + kBlock);
        // the block's centre and the largest distance of its candidates from it
        const Eigen::Vector3d half(x1 - 1 - x0, y1 - 1 - y0, z1 - 1 - z0);
        const Eigen::Vector3d centre =
            rotation_t_ * (Eigen::Vector3d(grid.x_min + x0 * grid.step, grid.y_min + y0 * grid.step,
                                           grid.z_min + z0 * grid.step) +
                           0.5 * grid.step * half);
        const std::size_t m =
            points_that_may_land(all_.x.data(), all_.y.data(), all_.z.data(), points(), centre.x(), centre.y(),
                                 centre.z(), 0.5 * grid.step * half.norm(), grid_, fine_.data_sat, s.bounds,
                                 s.kept.data());
        for (std::size_t i = 0; i < m; ++i) {
          s.x[i] = all_.x[s.kept[i]];
          s.y[i] = all_.y[s.kept[i]];
          s.z[i] = all_.z[s.kept[i]];
        }
        for (int ix = x0; ix < x1; ++ix) {
          for (int iy = y0; iy < y1; ++iy) {
            for (int iz = z0; iz < z1; ++iz) {
              const std::size_t k = (static_cast<std::size_t>(ix) * ny + iy) * nz + iz;
              const Eigen::Vector3d c = rotation_t_ * grid.at(k);
              result.costs[k] = score(fine_, static_cast<float>(c.x()), static_cast<float>(c.y()),
                                      static_cast<float>(c.z()), s, &overlaps[k], s.x.data(), s.y.data(),
                                      s.z.data(), m);
            }
          }
        }
      }
    } catch (...) {
#pragma omp critical
      error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
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
          Scratch scratch(used.current.size(), points());
          for (std::size_t k = begin; k < end; ++k) {
            costs[k] = score(used, grid.at(candidates[k]), scratch, &overlaps[k]);
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
