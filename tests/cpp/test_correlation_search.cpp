// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The rubble correlation search (eq. 4): a known offset found exactly, bad input, the virtual
// S-DEM and the exhaustive search against the implementation it replaced, candidate by candidate.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

#include "kiseki/terrain/correlation_search.hpp"
#include "kiseki/terrain/global_map.hpp"
#include "kiseki/terrain/hough_line_removal.hpp"
#include "kiseki/terrain/sphere_elevation_map.hpp"
#include "kiseki/terrain/virtual_sdem.hpp"
#include "terrain_scenes.hpp"

namespace kiseki {
namespace {

using test::kDeg;
using test::mound_floor;

TEST(CorrelationSearch, ExhaustiveAndCoarseToFineFindAKnownOffsetExactly) {
  SphereGrid g;
  const auto prev = SphereElevationMap::from_points(g, mound_floor(4));
  const Eigen::Matrix3Xd points = prev.to_points();
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(15 * kDeg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-10 * kDeg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-2 * kDeg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d truth(0.36, 0.30, 0.06);
  const Eigen::Matrix3Xd moved = R.transpose() * (points.colwise() - truth);
  const auto current = SphereElevationMap::from_points(g, moved);
  const CorrelationSearch search(points, current, R);
  ASSERT_EQ(TranslationGrid{}.size(), 56916u);  // the paper's grid (searched whole in the Python tests)
  TranslationGrid grid;  // a part of it around the truth, small enough for the sanitizer build
  grid.x_min = 0.20, grid.x_max = 0.50, grid.y_min = 0.10, grid.y_max = 0.50, grid.z_min = -0.10, grid.z_max = 0.20;
  const auto all = search.exhaustive(grid);
  EXPECT_LT((all.translation - truth).norm(), 1e-9);
  EXPECT_EQ(all.costs.size(), grid.size());
  const auto fast = search.coarse_to_fine(grid);
  EXPECT_LT((fast.translation - truth).norm(), 1e-9);
  EXPECT_LT(fast.evaluated, grid.size() / 2);
  // the same costs on one thread and on two
  CorrelationOptions one;
  one.threads = 1;
  TranslationGrid small;
  small.x_max = 0.2;
  small.y_min = small.z_min = -0.1;
  small.y_max = small.z_max = 0.1;
  EXPECT_EQ(CorrelationSearch(points, current, R, one).exhaustive(small).costs, search.exhaustive(small).costs);
}

TEST(CorrelationSearch, BadInputThrows) {
  SphereGrid g;
  const auto map = SphereElevationMap::from_points(g, mound_floor(5, 2000));
  EXPECT_THROW(CorrelationSearch(Eigen::Matrix3Xd(3, 0), map, Eigen::Matrix3d::Identity()), std::invalid_argument);
  EXPECT_THROW(CorrelationSearch(map.to_points(), SphereElevationMap(g), Eigen::Matrix3d::Identity()),
               std::invalid_argument);
  EXPECT_THROW(CorrelationSearch(map.to_points(), map, 2.0 * Eigen::Matrix3d::Identity()), std::invalid_argument);
  TranslationGrid zero;
  zero.step = 0.0;
  const CorrelationSearch search(map.to_points(), map, Eigen::Matrix3d::Identity());
  EXPECT_THROW(search.exhaustive(zero), std::invalid_argument);
  EXPECT_THROW(search.coarse_to_fine(TranslationGrid{}, 0), std::invalid_argument);
}

/// A scene after plane removal: the previous map sees the whole mound floor, the current one
/// (moved by `truth`, turned by R) only the mounds, so that most previous points land in cells
/// without data and the exhaustive search leaves many of them out.
struct SparseScene {
  SphereGrid g;
  Eigen::Matrix3Xd points;  ///< the previous map's points
  Eigen::Matrix3d R;
  SphereElevationMap current{SphereGrid{}};
  SparseScene() {
    R = (Eigen::AngleAxisd(15 * kDeg, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(-10 * kDeg, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(-2 * kDeg, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    points = SphereElevationMap::from_points(g, mound_floor(4, 8000)).to_points();
    const Eigen::Vector3d truth(0.36, 0.30, 0.06);
    std::vector<Eigen::Index> mounds;
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      if (points(2, i) > -0.44) mounds.push_back(i);
    }
    Eigen::Matrix3Xd seen(3, static_cast<Eigen::Index>(mounds.size()));
    for (std::size_t k = 0; k < mounds.size(); ++k) seen.col(static_cast<Eigen::Index>(k)) = points.col(mounds[k]);
    current = SphereElevationMap::from_points(g, R.transpose() * (seen.colwise() - truth));
  }
};

/// Eq. 4 at one candidate as kiseki computed it before the exhaustive search worked in blocks
/// of candidates and slots of cells with data: every point projected (the same eq. 3 in float),
/// a z-buffer over every cell, the sum in the order of each cell's first point.
double previous_eq4(const SparseScene& s, const Eigen::Vector3d& t, CorrelationCost cost, std::size_t* overlap) {
  const Eigen::Matrix3Xd turned = s.R.transpose() * s.points;
  const auto n = static_cast<std::size_t>(turned.cols());
  std::vector<float> px(n), py(n), pz(n), range(n);
  for (std::size_t i = 0; i < n; ++i) {
    px[i] = static_cast<float>(turned(0, static_cast<Eigen::Index>(i)));
    py[i] = static_cast<float>(turned(1, static_cast<Eigen::Index>(i)));
    pz[i] = static_cast<float>(turned(2, static_cast<Eigen::Index>(i)));
  }
  const Eigen::Vector3d c = s.R.transpose() * t;
  std::vector<int> cell(n);
  project_points(px.data(), py.data(), pz.data(), n, static_cast<float>(c.x()), static_cast<float>(c.y()),
                 static_cast<float>(c.z()), CellProjection(s.g, 1, s.g.rows(), s.g.cols()), cell.data(), range.data());
  std::vector<float> zbuffer(s.g.cells() + 1, std::numeric_limits<float>::infinity());
  std::vector<int> touched;
  for (std::size_t i = 0; i < n; ++i) {
    float& slot = zbuffer[static_cast<std::size_t>(cell[i])];
    if (std::isinf(slot)) touched.push_back(cell[i]);
    slot = std::min(slot, range[i]);
  }
  double sum = 0, weights = 0;
  *overlap = 0;
  for (int k : touched) {
    const auto at = static_cast<std::size_t>(k);
    if (at == s.g.cells() || std::isnan(s.current.ranges()[at])) continue;  // outside, or no data
    float w = static_cast<float>(std::cos(std::abs(s.g.phi_min_deg + (k % s.g.cols()) * s.g.step_deg) * kDeg));
    if (w <= 0) w = 1e-6f;
    const double d = static_cast<double>(zbuffer[at]) - static_cast<float>(s.current.ranges()[at]);
    sum += d * d * w;
    weights += w;
    ++*overlap;
  }
  if (*overlap < 50) return std::numeric_limits<double>::infinity();
  return cost == CorrelationCost::sum ? sum : sum / weights;
}

TEST(VirtualSdem, PointsLeftOutCannotLandInACellWithData) {
  const SparseScene s;
  const auto n = static_cast<std::size_t>(s.points.cols());
  std::vector<float> px(n), py(n), pz(n), range(n);
  for (std::size_t i = 0; i < n; ++i) {
    px[i] = static_cast<float>(s.points(0, static_cast<Eigen::Index>(i)));
    py[i] = static_cast<float>(s.points(1, static_cast<Eigen::Index>(i)));
    pz[i] = static_cast<float>(s.points(2, static_cast<Eigen::Index>(i)));
  }
  const int cols = s.g.cols();
  std::vector<int> sat((static_cast<std::size_t>(s.g.rows()) + 1) * (cols + 1), 0);
  for (int row = 0; row < s.g.rows(); ++row) {
    for (int col = 0; col < cols; ++col) {
      const std::size_t at = static_cast<std::size_t>(row + 1) * (cols + 1) + col + 1;
      sat[at] = !std::isnan(s.current.range(row, col)) + sat[at - 1] + sat[at - cols - 1] - sat[at - cols - 2];
    }
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ux(0.0, 0.7), uy(-0.5, 0.5), uz(-0.3, 0.3), unit(-1.0, 1.0);
  std::vector<int> scratch, cell(n);
  std::vector<std::uint32_t> kept(n);
  const double rho = 0.052;  // a block of 4 x 4 x 4 candidates 2 cm apart
  std::size_t left_out = 0;
  for (int block = 0; block < 20; ++block) {
    const Eigen::Vector3d c0(ux(rng), uy(rng), uz(rng));
    const std::size_t m = points_that_may_land(px.data(), py.data(), pz.data(), n, c0.x(), c0.y(), c0.z(), rho, s.g,
                                               sat, scratch, kept.data());
    left_out += n - m;
    const std::set<std::uint32_t> may(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(m));
    for (int k = 0; k < 30; ++k) {  // centres within rho, some on its surface
      Eigen::Vector3d d(unit(rng), unit(rng), unit(rng));
      d *= rho / d.norm() * (k % 3 == 0 ? 1.0 : std::abs(unit(rng)));
      const Eigen::Vector3d c = c0 + d;
      project_points(px.data(), py.data(), pz.data(), n, static_cast<float>(c.x()), static_cast<float>(c.y()),
                     static_cast<float>(c.z()), CellProjection(s.g, 1, s.g.rows(), s.g.cols()), cell.data(), range.data());
      for (std::size_t i = 0; i < n; ++i) {
        const auto at = static_cast<std::size_t>(cell[i]);
        if (at < s.g.cells() && !std::isnan(s.current.ranges()[at])) {
          ASSERT_TRUE(may.count(static_cast<std::uint32_t>(i))) << "point " << i << " lands in cell " << at;
        }
      }
    }
  }
  EXPECT_GT(left_out, 20 * n / 4);  // the bound leaves out a real share of the points
}

TEST(VirtualSdem, Eq4SumsAddSlotJToLaneJMod8BitForBit) {
  // The reference: eight scalar double sums, slot j into sum j % 8 in slot order, the eight
  // added last in lane order; the vectorised pass must give the same bits on every CPU.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> range(0.2f, 5.0f), weight(1e-6f, 1.0f), coin(0.0f, 1.0f);
  const float inf = std::numeric_limits<float>::infinity();
  for (const std::size_t slots : {8u, 64u, 3136u}) {
    std::vector<float> zbuffer(slots), current(slots), w(slots);
    double lane_sum[8] = {}, lane_weight[8] = {};
    std::size_t hits = 0;
    for (std::size_t j = 0; j < slots; ++j) {
      zbuffer[j] = coin(rng) < 0.4f ? inf : range(rng);
      current[j] = range(rng);
      w[j] = coin(rng) < 0.05f ? 0.0f : weight(rng);  // padding slots carry weight 0
      if (std::isinf(zbuffer[j])) continue;
      const double d = static_cast<double>(zbuffer[j]) - static_cast<double>(current[j]);
      lane_sum[j % 8] += d * d * static_cast<double>(w[j]);
      lane_weight[j % 8] += static_cast<double>(w[j]);
      ++hits;
    }
    double want_sum = 0, want_weight = 0;
    for (int l = 0; l < 8; ++l) want_sum += lane_sum[l], want_weight += lane_weight[l];
    const Eq4Sums got = eq4_sums(zbuffer.data(), current.data(), w.data(), slots);
    EXPECT_EQ(got.sum, want_sum) << slots;
    EXPECT_EQ(got.weights, want_weight) << slots;
    EXPECT_EQ(got.shared, hits) << slots;
    for (std::size_t j = 0; j < slots; ++j) ASSERT_TRUE(std::isinf(zbuffer[j]) && zbuffer[j] > 0) << j;  // reset
  }
}

TEST(CorrelationSearch, ExhaustiveEqualsThePreviousImplementationAtEveryCandidate) {
  const SparseScene s;
  TranslationGrid grid;  // 7 x 11 x 7: whole and partial blocks of 4
  grid.x_min = 0.30, grid.x_max = 0.42, grid.y_min = 0.20, grid.y_max = 0.40, grid.z_min = 0.0, grid.z_max = 0.12;
  for (const CorrelationCost cost : {CorrelationCost::sum, CorrelationCost::mean}) {
    CorrelationOptions options;
    options.cost = cost;
    const CorrelationSearch search(s.points, s.current, s.R, options);
    const auto all = search.exhaustive(grid);
    ASSERT_EQ(all.costs.size(), grid.size());
    std::size_t best = 0, best_overlap = 0, finite = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < grid.size(); ++k) {
      std::size_t overlap = 0;
      const double want = previous_eq4(s, grid.at(k), cost, &overlap);
      if (std::isinf(want)) {
        EXPECT_TRUE(std::isinf(all.costs[k])) << k;
        continue;
      }
      ++finite;
      EXPECT_NEAR(all.costs[k], want, 1e-12 * want) << k;  // the sum's order differs
      std::size_t got_overlap = 0;
      EXPECT_EQ(search.cost(grid.at(k), &got_overlap), all.costs[k]) << k;  // all points, bit for bit
      EXPECT_EQ(got_overlap, overlap) << k;
      if (want < best_cost) best = k, best_cost = want, best_overlap = overlap;
    }
    EXPECT_GT(finite, grid.size() / 2);
    EXPECT_EQ(all.index, best);
    EXPECT_EQ(all.overlap, best_overlap);
    // one thread and two: the same costs, bit for bit
    CorrelationOptions one = options;
    one.threads = 1;
    CorrelationOptions two = options;
    two.threads = 2;
    EXPECT_EQ(CorrelationSearch(s.points, s.current, s.R, one).exhaustive(grid).costs, all.costs);
    EXPECT_EQ(CorrelationSearch(s.points, s.current, s.R, two).exhaustive(grid).costs, all.costs);
  }
}

}  // namespace
}  // namespace kiseki
