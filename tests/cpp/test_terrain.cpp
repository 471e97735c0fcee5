// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
// The rubble pipeline: the sphere elevation map, Hough and PCL plane removal, the global voxel
// map, PCL registration and the PCD reader (the correlation search: test_correlation_search.cpp).
#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>

#include "kiseki/io/pcd_file.hpp"
#include "kiseki/sim/octree_world.hpp"
#include "kiseki/terrain/correlation_search.hpp"
#include "kiseki/terrain/global_map.hpp"
#include "kiseki/terrain/hough_line_removal.hpp"
#include "kiseki/terrain/pcl_plane_removal.hpp"
#include "kiseki/terrain/pcl_registration.hpp"
#include "kiseki/terrain/sphere_elevation_map.hpp"
#include "kiseki/terrain/virtual_sdem.hpp"
#include "terrain_scenes.hpp"

namespace kiseki {
namespace {

using test::kDeg;
using test::mound_floor;

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
  // a wall of points 2.03 m ahead of a sensor at (1, 0, 0.5), seen once; every point lies
  // 0.025 m or more inside its 0.1 m voxel, so its voxel is unambiguous
  Eigen::Matrix3Xd wall(3, 21 * 21);
  for (int i = 0; i < 21; ++i) {
    for (int j = 0; j < 21; ++j) wall.col(i * 21 + j) << 2.03, -0.475 + 0.05 * i, -0.475 + 0.05 * j;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << 1.0, 0.0, 0.5;
  GlobalVoxelMap map(0.1, 5.0);
  map.insert(wall, pose);
  // the occupied voxels are exactly those holding an end (keys: floor(coordinate / 0.1))
  const auto key = [](const Eigen::Vector3d& p) {
    return std::array<long, 3>{std::lround(std::floor(p.x() / 0.1)), std::lround(std::floor(p.y() / 0.1)),
                               std::lround(std::floor(p.z() / 0.1))};
  };
  std::set<std::array<long, 3>> ends, occupied;
  for (Eigen::Index k = 0; k < wall.cols(); ++k) ends.insert(key(pose * Eigen::Vector3d(wall.col(k))));
  const Eigen::Matrix3Xd centres = map.occupied_centres();
  for (Eigen::Index k = 0; k < centres.cols(); ++k) occupied.insert(key(centres.col(k)));
  EXPECT_EQ(occupied, ends);
  EXPECT_EQ(map.occupied_leaves(), ends.size());
  EXPECT_GT(map.free_leaves(), 0u);
  // written and read back by OctoMap: the same occupied voxels; a ray along the sensor's axis
  // passes the way the beams crossed and stops at the wall's voxel face, x = 3.0
  const auto dir = std::filesystem::temp_directory_path() / "kiseki_test_global_map";
  std::filesystem::create_directories(dir);
  map.write_binary((dir / "map.bt").string());
  const OctreeWorld back = OctreeWorld::read_binary((dir / "map.bt").string());
  std::filesystem::remove_all(dir);
  EXPECT_EQ(back.occupied_leaves(), ends.size());
  EXPECT_EQ(back.resolution(), 0.1);
  EXPECT_NEAR(back.cast(pose.translation() + Eigen::Vector3d(0, 0.025, 0.025), Eigen::Vector3d::UnitX(), 10.0), 2.0,
              0.1 + 1e-9);
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

TEST(PcdFile, RefusesAHeaderThatDoesNotDescribeItsData) {
  // A header declaring fewer points than the file holds, a POINTS that is not WIDTH x HEIGHT,
  // or text data declared binary: each once read as a smaller or garbled cloud without a word.
  const auto dir = std::filesystem::temp_directory_path() / "kiseki_test_pcd_header";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "cloud.pcd").string();
  const auto read_text = [&](const std::string& width, const std::string& points, const std::string& data,
                             const std::string& body) {
    {
      std::ofstream out(path, std::ios::binary);
      out << "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " << width
          << "\nHEIGHT 1\n" << points << "DATA " << data << "\n" << body;
    }
    return read_pcd(path);
  };
  const auto refused = [&](const std::string& width, const std::string& points, const std::string& data,
                           const std::string& body, const std::string& why) {
    try {
      read_text(width, points, data, body);
      ADD_FAILURE() << "read: WIDTH " << width << ", " << points << data;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  const std::string three = "0 0 0\n1 2 3\n4 5 6\n";
  EXPECT_EQ(read_text("3", "POINTS 3\n", "ascii", three + "\n  \n").points.cols(), 3);  // blank lines after
  EXPECT_EQ(read_text("3", "", "ascii", three).points.cols(), 3);                        // POINTS may be left out
  refused("3", "POINTS 5\n", "ascii", three, "POINTS 5 is not WIDTH x HEIGHT, 3");
  refused("3", "POINTS -5\n", "ascii", three, "POINTS -5");
  refused("3", "POINTS 0\n", "ascii", three, "POINTS");
  refused("2", "POINTS 2\n", "ascii", three, "more data lines than its 2 points");
  refused("2", "", "ascii", three, "more data lines than its 2 points");
  // 3 points of 12 bytes are 36 bytes; the text holds 18
  refused("3", "POINTS 3\n", "binary", three, "truncated");
  refused("1", "POINTS 1\n", "binary", three, "12 bytes of binary data declared, 18 present");
  // older PCL writers padded binary files with zeros up to a page: read, as PCL reads them;
  // bytes that are not zeros are data the header does not declare
  write_pcd(path, mound_floor(2, 20));
  const PcdCloud whole = read_pcd(path);
  {
    std::ofstream pad(path, std::ios::binary | std::ios::app);
    pad << std::string(4000, '\0');
  }
  const PcdCloud padded = read_pcd(path);
  EXPECT_EQ(padded.points, whole.points);
  {
    std::ofstream more(path, std::ios::binary | std::ios::app);
    more << "x";
  }
  EXPECT_THROW(read_pcd(path), std::runtime_error);
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
