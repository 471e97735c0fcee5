// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include "kiseki/io/pcd_file.hpp"
#include "kiseki/terrain/correlation_search.hpp"
#include "kiseki/terrain/global_map.hpp"
#include "kiseki/terrain/hough_line_removal.hpp"
#include "kiseki/terrain/pcl_plane_removal.hpp"
#include "kiseki/terrain/pcl_registration.hpp"
#include "kiseki/terrain/sphere_elevation_map.hpp"
#include "kiseki/terrain/virtual_sdem.hpp"

namespace kiseki {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// A floor 0.5 m below the sensor with smooth mounds, sampled densely.
Eigen::Matrix3Xd mound_floor(unsigned seed, int n = 20000) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-2.5, 3.5), uy(-3.0, 3.0);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) {
    const double x = ux(rng), y = uy(rng);
    p.col(i) << x, y, -0.5 + 0.25 * std::exp(-((x - 1.2) * (x - 1.2) + (y - 0.8) * (y - 0.8)) / 0.3) +
                          0.15 * std::exp(-((x - 2.0) * (x - 2.0) + (y + 1.1) * (y + 1.1)) / 0.2) +
                          0.05 * std::sin(2.0 * x) * std::cos(1.5 * y);
  }
  return p;
}

TEST(SphereGrid, PaperGridHas151By181Cells) {
  SphereGrid g;
  EXPECT_EQ(g.rows(), 151);
  EXPECT_EQ(g.cols(), 181);
  EXPECT_EQ(g.cell_of(-120 * kDeg, -90 * kDeg), 0);
  EXPECT_EQ(g.cell_of(30 * kDeg, 90 * kDeg), 151L * 181 - 1);
  EXPECT_EQ(g.cell_of(31 * kDeg, 0.0), -1);
  SphereGrid zero;
  zero.step_deg = 0.0;
  EXPECT_THROW(zero.validate(), std::invalid_argument);
  SphereGrid nan;
  nan.max_range = std::nan("");
  EXPECT_THROW(nan.validate(), std::invalid_argument);
}

TEST(SphereElevationMap, RangesToPointsToRangesIsExact) {
  SphereGrid g;
  std::vector<double> ranges(g.cells());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.2, 4.99);
  for (auto& r : ranges) r = u(rng);
  ranges[10] = std::nan("");
  ranges[11] = 5.0;  // at the cut: no data
  const auto map = SphereElevationMap::from_ranges(g, ranges);
  EXPECT_EQ(map.valid_cells(), g.cells() - 2);
  std::vector<long> cells;
  const Eigen::Matrix3Xd p = map.to_points(&cells);
  // eq. 2 with sin(phi) for y, checked at one cell by hand
  const long c = cells[5000];
  const double th = g.theta(static_cast<int>(c / g.cols())), ph = g.phi(static_cast<int>(c % g.cols()));
  const double r = ranges[static_cast<std::size_t>(c)];
  EXPECT_NEAR(p(0, 5000), r * std::cos(th) * std::cos(ph), 1e-12);
  EXPECT_NEAR(p(1, 5000), r * std::sin(ph), 1e-12);
  EXPECT_NEAR(p(2, 5000), r * std::sin(th) * std::cos(ph), 1e-12);
  const auto back = SphereElevationMap::from_points(g, p);
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    if (std::isnan(map.ranges()[i])) {
      EXPECT_TRUE(std::isnan(back.ranges()[i]));
    } else {
      EXPECT_NEAR(back.ranges()[i], map.ranges()[i], 1e-12);
    }
  }
}

TEST(SphereElevationMap, RefusesNanPointsAndAttitudes) {
  SphereGrid g;
  Eigen::Matrix3Xd p(3, 1);
  p << 1.0, std::nan(""), 0.0;
  EXPECT_THROW(SphereElevationMap::from_points(g, p), std::invalid_argument);
  Eigen::Matrix3d nan_attitude = Eigen::Matrix3d::Identity();
  nan_attitude(0, 0) = std::nan("");
  EXPECT_THROW(SphereElevationMap::from_points(g, mound_floor(1, 10), nan_attitude), std::invalid_argument);
  EXPECT_THROW(SphereElevationMap::median({}), std::invalid_argument);
}

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

/// A corridor's tilt scan: walls at y = +-1 m (planes: lines in every tilt scan) and a 10 cm
/// box on the floor, as seen from a sensor 0.5 m above the floor.
SphereElevationMap corridor_with_box(const SphereGrid& g, std::vector<char>* box_cells) {
  std::vector<double> ranges(g.cells(), std::nan(""));
  box_cells->assign(g.cells(), 0);
  for (int row = 0; row < g.rows(); ++row) {
    for (int col = 0; col < g.cols(); ++col) {
      const double th = g.theta(row), ph = g.phi(col);
      const Eigen::Vector3d d(std::cos(th) * std::cos(ph), std::sin(ph), std::sin(th) * std::cos(ph));
      double best = 1e9;
      bool box = false;
      if (std::abs(d.y()) > 1e-9) best = std::min(best, 1.0 / std::abs(d.y()));  // the walls
      if (d.z() < -1e-9) best = std::min(best, 0.5 / -d.z());                     // the floor
      // the box: x in [1.5, 1.8], y in [-0.15, 0.15], z in [-0.5, -0.4], slab intersection
      double t0 = 0, t1 = 1e9;
      const Eigen::Vector3d lo(1.5, -0.15, -0.5), hi(1.8, 0.15, -0.4);
      for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          if (0 < lo[k] || 0 > hi[k]) t0 = 1e9;
          continue;
        }
        const double a = lo[k] / d[k], b = hi[k] / d[k];
        t0 = std::max(t0, std::min(a, b));
        t1 = std::min(t1, std::max(a, b));
      }
      if (t0 <= t1 && t0 < best) best = t0, box = true;
      if (best < g.max_range) {
        ranges[static_cast<std::size_t>(row) * g.cols() + col] = best;
        (*box_cells)[static_cast<std::size_t>(row) * g.cols() + col] = box;
      }
    }
  }
  return SphereElevationMap::from_ranges(g, ranges);
}

TEST(HoughLineRemoval, RemovesTheWallsAndKeepsMostOfASmallBox) {
  SphereGrid g;
  std::vector<char> box;
  const auto map = corridor_with_box(g, &box);
  const auto result = remove_lines_hough(map, HoughLineParams{});
  std::size_t box_total = 0, box_kept = 0, removed = 0;
  for (std::size_t i = 0; i < g.cells(); ++i) {
    box_total += box[i];
    box_kept += box[i] && !result.removed[i];
    removed += result.removed[i];
  }
  ASSERT_GT(box_total, 20u);
  EXPECT_GT(removed, map.valid_cells() * 8 / 10);  // walls and flat floor: nearly everything
  EXPECT_GT(box_kept, box_total / 2);
  EXPECT_GT(result.lines, 151u);
  HoughLineParams bad;
  bad.rho_step = 0.0;
  EXPECT_THROW(remove_lines_hough(map, bad), std::invalid_argument);
}

TEST(PclPlaneRemoval, FindsTheCorridorPlanesAndIsSeeded) {
  SphereGrid g;
  std::vector<char> box;
  const auto map = corridor_with_box(g, &box);
  std::vector<long> cells;
  const Eigen::Matrix3Xd points = map.to_points(&cells);
  const auto a = remove_planes_pcl(points, PclPlaneParams{}, 1);
  ASSERT_GE(a.planes.size(), 3u);
  // the three largest planes are the floor (z = -0.5) and the walls (y = +-1), in some order
  int floor = 0, walls = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector4d c = a.planes[k].coefficients * (a.planes[k].coefficients[3] < 0 ? -1 : 1);
    if (std::abs(std::abs(c[2]) - 1) < 0.01 && std::abs(c[3] - 0.5) < 0.02) ++floor;
    if (std::abs(std::abs(c[1]) - 1) < 0.01 && std::abs(c[3] - 1.0) < 0.02) ++walls;
  }
  EXPECT_EQ(floor, 1);
  EXPECT_EQ(walls, 2);
  const auto b = remove_planes_pcl(points, PclPlaneParams{}, 1);
  EXPECT_EQ(a.removed, b.removed);
  PclPlaneParams bad;
  bad.min_inliers = 2;
  EXPECT_THROW(remove_planes_pcl(points, bad, 1), std::invalid_argument);
}

TEST(GlobalVoxelMap, RaysMarkTheirEndsOccupiedAndTheWayFree) {
  // a wall of points 2 m ahead of a sensor at (1, 0, 0.5), seen once
  Eigen::Matrix3Xd wall(3, 21 * 21);
  for (int i = 0; i < 21; ++i) {
    for (int j = 0; j < 21; ++j) wall.col(i * 21 + j) << 2.0, -0.5 + 0.05 * i, -0.5 + 0.05 * j;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << 1.0, 0.0, 0.5;
  GlobalVoxelMap map(0.1, 5.0);
  map.insert(wall, pose);
  const Eigen::Matrix3Xd occupied = map.occupied_centres();
  ASSERT_GT(occupied.cols(), 0);
  for (Eigen::Index k = 0; k < occupied.cols(); ++k) EXPECT_NEAR(occupied(0, k), 3.0, 0.1);  // x = 1 + 2
  EXPECT_GT(map.free_leaves(), 0u);
  const auto dir = std::filesystem::temp_directory_path() / "kiseki_test_global_map";
  std::filesystem::create_directories(dir);
  map.write_binary((dir / "map.bt").string());
  EXPECT_GT(std::filesystem::file_size(dir / "map.bt"), 100u);
  std::filesystem::remove_all(dir);
  EXPECT_THROW(GlobalVoxelMap(0.0, 5.0), std::invalid_argument);
  Eigen::Matrix3Xd nan(3, 1);
  nan << 1.0, std::nan(""), 0.0;
  EXPECT_THROW(map.insert(nan, pose), std::invalid_argument);
}

TEST(PclRegistration, IcpAndGicpRecoverAKnownMotion) {
  const auto g = SphereGrid{};
  const Eigen::Matrix3Xd target = SphereElevationMap::from_points(g, mound_floor(8, 8000)).to_points();
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.rotate(Eigen::AngleAxisd(3 * kDeg, Eigen::Vector3d::UnitZ()));
  motion.translation() << 0.08, -0.05, 0.02;
  const Eigen::Matrix3Xd source = motion.inverse() * target;  // the target seen from the moved pose
  for (const char* method : {"icp", "gicp"}) {
    PclRegistrationParams p;
    p.method = method;
    const auto r = register_pcl(source, target, Eigen::Isometry3d::Identity(), p);
    EXPECT_TRUE(r.converged) << method;
    EXPECT_LT((r.transform.translation() - motion.translation()).norm(), 0.01) << method;
  }
  PclRegistrationParams bad;
  bad.method = "ndt";
  EXPECT_THROW(register_pcl(source, target, Eigen::Isometry3d::Identity(), bad), std::invalid_argument);
}

TEST(PcdFile, RoundTripAndCorruptFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "kiseki_test_pcd";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "cloud.pcd").string();
  const Eigen::Matrix3Xd points = mound_floor(6, 500);
  write_pcd(path, points);
  const PcdCloud back = read_pcd(path);
  ASSERT_EQ(back.points.cols(), 500);
  EXPECT_LT((back.points - points).cwiseAbs().maxCoeff(), 1e-6);  // float32 in the file
  EXPECT_EQ(back.width, 500u);
  // truncated: the data cut in half
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 3000);
  EXPECT_THROW(read_pcd(path), std::runtime_error);
  {
    std::ofstream garbage(path);
    garbage << "not a pcd\n";
  }
  EXPECT_THROW(read_pcd(path), std::runtime_error);
  EXPECT_THROW(read_pcd((dir / "missing.pcd").string()), std::runtime_error);
  EXPECT_THROW(write_pcd(path, Eigen::Matrix3Xd(3, 0)), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(PcdFile, ReadsTheRecordedCloudsAsPclDoes) {
  int checked = 0;
  for (const char* name : {"office1.pcd", "sac_plane_test.pcd", "table_scene_mug_stereo_textured.pcd"}) {
    const std::string path = std::string(KISEKI_SHARED_DATA) + "/pcd/" + name;
    if (!std::filesystem::exists(path)) continue;
    pcl::PointCloud<pcl::PointXYZ> reference;
    ASSERT_EQ(pcl::io::loadPCDFile(path, reference), 0) << path;
    const PcdCloud cloud = read_pcd(path);
    EXPECT_EQ(cloud.width, reference.width);
    EXPECT_EQ(cloud.height, reference.height);
    Eigen::Index k = 0;
    std::size_t non_finite = 0;
    for (const auto& p : reference) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ++non_finite;
        continue;
      }
      ASSERT_LT(k, cloud.points.cols());
      EXPECT_EQ(static_cast<float>(cloud.points(0, k)), p.x);  // PCL parses ASCII to float
      EXPECT_EQ(static_cast<float>(cloud.points(2, k)), p.z);
      ++k;
    }
    EXPECT_EQ(k, cloud.points.cols());
    EXPECT_EQ(non_finite, cloud.non_finite);
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "the recorded PCD clouds are not beside the repository";
}

}  // namespace
}  // namespace kiseki
