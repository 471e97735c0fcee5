// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>

#include <octomap/OcTree.h>
#include <opencv2/core.hpp>

#include "kiseki/core/angle.hpp"
#include "kiseki/core/random.hpp"
#include "kiseki/sim/box_world.hpp"
#include "kiseki/sim/depth_camera.hpp"
#include "kiseki/sim/octree_world.hpp"
#include "kiseki/io/octomap_file.hpp"

using namespace kiseki;

namespace {

std::vector<Box> random_boxes(std::uint64_t seed, int n) {
  Random r(seed);
  std::vector<Box> boxes;
  for (int i = 0; i < n; ++i) {
    Box b;
    b.center = {r.uniform(-5, 5), r.uniform(-5, 5), r.uniform(0, 2)};
    b.half_size = {r.uniform(0.05, 0.5), r.uniform(0.05, 0.5), r.uniform(0.05, 0.5)};
    b.rotation = (Eigen::AngleAxisd(r.uniform(-kPi, kPi), Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(r.uniform(-0.5, 0.5), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    boxes.push_back(b);
  }
  return boxes;
}

Eigen::Vector3d random_direction(Random& r) {
  Eigen::Vector3d d(r.normal(), r.normal(), r.normal());
  return d.normalized();
}

}  // namespace

TEST(Box, IntersectionAgreesWithMarchingAndContains) {
  const auto boxes = random_boxes(1, 20);
  Random r(2);
  for (const Box& b : boxes) {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector3d o = b.center + Eigen::Vector3d(r.uniform(-2, 2), r.uniform(-2, 2), r.uniform(-2, 2));
      const Eigen::Vector3d d = random_direction(r);
      const double t = b.intersect(o, d);
      // Reference: march in 1 cm steps to the first point inside, then bisect the entry.
      double march = std::numeric_limits<double>::infinity();
      for (double s = 0.0; s < 5.0; s += 1e-2) {
        if (!b.contains(o + s * d)) continue;
        double lo = std::max(0.0, s - 1e-2), hi = s;
        if (b.contains(o + lo * d)) hi = lo;  // the ray starts inside
        for (int k = 0; k < 60 && hi > lo; ++k) {
          const double mid = 0.5 * (lo + hi);
          (b.contains(o + mid * d) ? hi : lo) = mid;
        }
        march = hi;
        break;
      }
      if (std::isinf(march)) {
        EXPECT_TRUE(std::isinf(t) || t > 5.0 - 1e-3 || !b.contains(o + (t + 1e-6) * d));
      } else {
        ASSERT_NEAR(t, march, 1e-9);
      }
    }
  }
}

TEST(BoxWorld, BvhCastEqualsLinearScanOverAllBoxes) {
  const auto boxes = random_boxes(3, 300);
  const BoxWorld world(boxes);
  Random r(4);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d o(r.uniform(-6, 6), r.uniform(-6, 6), r.uniform(-1, 3));
    const Eigen::Vector3d d = random_direction(r);
    double ref = 12.0;
    for (const Box& b : boxes) ref = std::min(ref, b.intersect(o, d));
    ASSERT_DOUBLE_EQ(world.cast(o, d, 12.0), ref);
  }
  EXPECT_THROW(world.cast({0, 0, 0}, {1, 1, 0}, 5.0), std::invalid_argument);
  Box bad;
  bad.half_size = {0.1, -0.1, 0.1};
  EXPECT_THROW(BoxWorld({bad}), std::invalid_argument);
}

TEST(BoxWorld, AxisAlignedBoxesAndAxisParallelRaysEqualTheLinearScan) {
  // walls and furniture are mostly axis-aligned (the cast skips their rotation), and a camera's
  // centre rays or a laser along a corridor have direction components of exactly +-0
  std::vector<Box> boxes = random_boxes(5, 200);
  for (std::size_t i = 0; i < boxes.size(); i += 2) boxes[i].rotation.setIdentity();
  const BoxWorld world(boxes);
  Random r(6);
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d o(r.uniform(-6, 6), r.uniform(-6, 6), r.uniform(-1, 3));
    Eigen::Vector3d d = random_direction(r);
    if (i % 3 == 0) d[i % 2] = (i % 4 == 0) ? 0.0 : -0.0;
    if (i % 5 == 0) d[2] = -0.0;
    d.normalize();
    if (i % 7 == 0) d = Eigen::Vector3d::Unit(i % 3) * ((i % 2) ? -1.0 : 1.0);
    double ref = 12.0;
    for (const Box& b : boxes) ref = std::min(ref, b.intersect(o, d));
    ASSERT_EQ(world.cast(o, d, 12.0), ref) << i;  // bit for bit
  }
}

TEST(BoxWorld, RasterizeBandSeesOnlyWhatIsInTheBand) {
  Box leg, top;
  leg.center = {1.0, 1.0, 0.35};
  leg.half_size = {0.05, 0.05, 0.35};  // 0 .. 0.7 m
  top.center = {1.5, 1.0, 0.75};
  top.half_size = {0.5, 0.3, 0.02};  // a table top at 0.73 .. 0.77 m
  const BoxWorld world({leg, top});
  OccupancyGrid low(40, 40, 0.05, Pose2(), kUnknown), high(40, 40, 0.05, Pose2(), kUnknown);
  world.rasterize_band(0.35, 0.45, low);
  world.rasterize_band(0.70, 0.80, high);
  EXPECT_EQ(low.value(20, 20), kOccupied);   // the leg at (1.0, 1.0)
  EXPECT_EQ(low.value(30, 20), kFree);       // under the table top
  EXPECT_EQ(high.value(30, 20), kOccupied);  // the top
  EXPECT_EQ(cv::countNonZero(low.cells() == kOccupied), 4);  // a 0.1 m leg = 2 x 2 cells
}

TEST(OctreeWorld, VoxelisedBoxesCastWithinAVoxelAndRoundTripThroughBt) {
  const auto boxes = random_boxes(5, 30);
  const BoxWorld world(boxes);
  const OctreeWorld octree = OctreeWorld::from_boxes(world, 0.05);
  EXPECT_GT(octree.occupied_leaves(), 0u);
  Random r(6);
  int compared = 0, agree = 0;
  const double tol = 2 * 0.05 * std::sqrt(3.0);  // a voxel diagonal plus the over-fill
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d o(r.uniform(-6, 6), r.uniform(-6, 6), r.uniform(-1, 3));
    if (world.occupied(o)) continue;
    const Eigen::Vector3d d = random_direction(r);
    const double exact = world.cast(o, d, 8.0), voxel = octree.cast(o, d, 8.0);
    if (exact >= 8.0) continue;
    ++compared;
    // No holes: the voxel map never lets a ray through a surface the boxes have...
    ASSERT_LE(voxel, exact + tol) << o.transpose() << " | " << d.transpose();
    // ...and mostly reports the same surface (grazing rays may clip an over-filled voxel).
    agree += std::abs(voxel - exact) <= tol;
  }
  EXPECT_GT(agree, 0.9 * compared);  // measured 94 % with these small random boxes
  EXPECT_GT(compared, 50);
  const std::string path = testing::TempDir() + "kiseki_world.bt";
  octree.write_binary(path);
  const OctreeWorld back = OctreeWorld::read_binary(path);
  EXPECT_EQ(back.occupied_leaves(), octree.occupied_leaves());
  EXPECT_DOUBLE_EQ(back.resolution(), 0.05);
  // Corrupt the tree data and read it back. Octomap writes a comment line after its first line
  // (offset 60 falls in it, and a file "corrupted" there still reads); the two bytes right after
  // the header's "data" line hold the root's child bits: zeroed, the root has no children and
  // the node count no longer matches the header's "size", which the reader must refuse.
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t data = bytes.find("\ndata\n");
  ASSERT_NE(data, std::string::npos);
  ASSERT_GT(bytes.size(), data + 8);
  bytes[data + 6] = '\0';
  bytes[data + 7] = '\0';
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  // OctoMap says why on stderr: the reason is in the error, and nothing reaches stderr.
  testing::internal::CaptureStderr();
  try {
    (void)OctreeWorld::read_binary(path);
    ADD_FAILURE() << "a .bt file whose root lost its children was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("corrupt or truncated"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("(OctoMap: Tree size mismatch"), std::string::npos) << e.what();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  std::FILE* g = std::fopen((path + ".txt").c_str(), "wb");
  std::fputs("not an octree\n", g);
  std::fclose(g);
  EXPECT_THROW(OctreeWorld::read_binary(path + ".txt"), std::runtime_error);
  EXPECT_THROW(OctreeWorld::read_binary("/nonexistent/x.bt"), std::runtime_error);
}

TEST(OctomapFile, WritesOctomapsOwnBytesAndNothingToStderr) {
  // the reference is OctoMap's own writer (writeBinaryConst), whose " done." on stderr is
  // swallowed here; kiseki's writer must give the same bytes and print nothing
  Random r(7);
  for (const double resolution : {0.05, 0.1, 0.123456789}) {
    octomap::OcTree tree(resolution);
    for (int i = 0; i < 400; ++i) {
      tree.updateNode(octomap::point3d(r.uniform(-3, 3), r.uniform(-3, 3), r.uniform(0, 2)), r.uniform(0, 1) < 0.7);
    }
    tree.toMaxLikelihood();
    tree.prune();
    std::ostringstream reference;
    testing::internal::CaptureStderr();
    ASSERT_TRUE(tree.writeBinaryConst(reference));
    const std::string said = testing::internal::GetCapturedStderr();  // why kiseki writes its own
    EXPECT_EQ(said.substr(said.size() - std::min<std::size_t>(said.size(), 7)), " done.\n");
    const std::string path = testing::TempDir() + "kiseki_octomap_file.bt";
    testing::internal::CaptureStderr();
    write_octomap_binary(tree, path);
    EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
    std::ifstream in(path, std::ios::binary);
    const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(written, reference.str()) << "resolution " << resolution;
    EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
    const OctreeWorld back = OctreeWorld::read_binary(path);
    EXPECT_NEAR(back.resolution(), resolution, 5e-6 * resolution);  // 6 significant digits, as OctoMap
  }
  // another kind of tree, or bytes after the tree: OctoMap read both as this tree
  const std::string path = testing::TempDir() + "kiseki_octomap_kind.bt";
  octomap::OcTree small(0.1);
  small.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
  write_octomap_binary(small, path);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto rewrite = [&](const std::string& content) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
  };
  const auto message = [&]() -> std::string {
    try {
      (void)OctreeWorld::read_binary(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "read";
  };
  EXPECT_EQ(message(), "read");
  std::string colour = bytes;
  colour.replace(colour.find("id OcTree"), 9, "id ColorOcTree");
  rewrite(colour);
  EXPECT_EQ(message(), path + ": an OctoMap tree of kind 'ColorOcTree', not OcTree (occupancy only)");
  std::string crlf = bytes;  // OctoMap reads its header word by word: a CR line end is read
  crlf.replace(crlf.find("id OcTree\n"), 10, "id  OcTree\r\n");
  rewrite(crlf + "\n");  // and a line end after the tree is no data
  EXPECT_EQ(message(), "read");
  rewrite(bytes + std::string(700, 'x'));
  EXPECT_EQ(message(), path + ": 700 bytes after the OctoMap tree (a damaged or concatenated file)");
  const std::string nowhere = testing::TempDir() + "no_such_folder/map.bt";
  EXPECT_THROW(write_octomap_binary(octomap::OcTree(0.1), nowhere), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(nowhere + ".partial"));
}

TEST(DepthCamera, BoxWorldImageEqualsOneCastPerPixel) {
  // the box world is rendered per tile against the boxes projected there, each clipped at half
  // the minimum range; the reference casts every pixel's ray against the whole world, as the
  // image's definition says. Cameras anywhere among the boxes, inside one, and 0.01-0.4 m from
  // a box's face (where the clipping must not hide it), with minimum ranges 0.3 m and 0.
  std::vector<Box> boxes = random_boxes(7, 120);
  for (std::size_t i = 0; i < boxes.size(); i += 3) boxes[i].rotation.setIdentity();
  const BoxWorld world(boxes);
  Random r(8);
  int hits = 0, frames = 0;
  for (const double min_range : {0.3, 0.0}) {
    const auto cam = PinholeCamera::from_fov(61, 37, 1.2, 0.9, min_range, 6.0);
    for (int k = 0; k < 90; ++k, ++frames) {
      Eigen::Vector3d origin(r.uniform(-6, 6), r.uniform(-6, 6), r.uniform(-0.5, 2.5));
      const Box& near = boxes[static_cast<std::size_t>(k) % boxes.size()];
      if (k % 3 == 1) origin = near.center;  // inside a box
      if (k % 3 == 2) {  // in front of a face, looking anywhere
        const double gap = 0.01 + 0.13 * (k % 4);
        origin = near.center + near.rotation.col(k % 3) * (near.half_size[k % 3] + gap);
      }
      const Eigen::Quaterniond q(Eigen::AngleAxisd(r.uniform(-kPi, kPi), random_direction(r)));
      const cv::Mat depth = render_depth(world, Pose3(origin, q), cam);
      const Eigen::Matrix3d rot = q.toRotationMatrix();
      for (int v = 0; v < cam.height; ++v) {
        for (int u = 0; u < cam.width; ++u) {
          const Eigen::Vector3d ray((u + 0.5 - cam.cx) / cam.fx, (v + 0.5 - cam.cy) / cam.fy,
                                    1.0);
          const double norm = ray.norm();
          const double z = world.cast(origin, rot * (ray / norm), cam.max_range * norm) / norm;
          const float expected =
              (z >= cam.min_range && z < cam.max_range) ? static_cast<float>(z) : 0.f;
          ASSERT_EQ(depth.at<float>(v, u), expected) << k << " " << u << " " << v;
          hits += expected > 0.f;
        }
      }
    }
  }
  EXPECT_GT(hits, frames * 61 * 37 / 10);  // the scenes are seen, not empty
  // small boxes just before, across and beyond the minimum range (where a clipping plane too
  // far out would drop them and show the wall behind), and one beside the camera
  for (const double min_range : {0.3, 0.0}) {
    const auto cam = PinholeCamera::from_fov(40, 30, 1.2, 0.9, min_range, 6.0);
    for (double z = 0.02; z < 0.8; z += 0.04) {
      Box wall, small, side;
      wall.center = {0.0, 0.0, 3.0};
      wall.half_size = {5.0, 5.0, 0.1};
      small.center = {0.1 * z, -0.05, z};
      small.half_size = {0.03, 0.03, 0.01};
      side.center = {0.2 + z, 0.0, 0.0};
      side.half_size = {0.1, 0.3, 0.3};
      const BoxWorld few({wall, small, side});
      const cv::Mat depth = render_depth(few, Pose3(), cam);
      for (int v = 0; v < cam.height; ++v) {
        for (int u = 0; u < cam.width; ++u) {
          const Eigen::Vector3d ray((u + 0.5 - cam.cx) / cam.fx, (v + 0.5 - cam.cy) / cam.fy,
                                    1.0);
          const double norm = ray.norm();
          const double d = few.cast(Eigen::Vector3d::Zero(), ray / norm, cam.max_range * norm);
          const float expected =
              (d / norm >= cam.min_range && d / norm < cam.max_range) ? static_cast<float>(d / norm)
                                                                      : 0.f;
          ASSERT_EQ(depth.at<float>(v, u), expected) << z << " " << u << " " << v;
        }
      }
    }
  }
}

TEST(DepthCamera, FlatWallGivesConstantZDepth) {
  Box wall;
  wall.center = {3.0, 0.0, 1.0};
  wall.half_size = {0.05, 5.0, 2.0};  // front face at x = 2.95
  const BoxWorld world({wall});
  // optical frame looking along world +x: z_opt = x, x_opt = -y, y_opt = -z
  Eigen::Matrix3d r;
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Pose3 pose(Eigen::Vector3d(0, 0, 1.0), Eigen::Quaterniond(r));
  const auto cam = PinholeCamera::from_fov(64, 48, 58.0 * kPi / 180, 45.0 * kPi / 180, 0.5, 10.0);
  const cv::Mat depth = render_depth(world, pose, cam);
  double lo, hi;
  cv::minMaxLoc(depth, &lo, &hi);
  EXPECT_NEAR(lo, 2.95, 1e-6);  // float32 image
  EXPECT_NEAR(hi, 2.95, 1e-6);
  const Pose3 far(Eigen::Vector3d(-8.0, 0, 1.0), Eigen::Quaterniond(r));  // wall at 10.95 m
  EXPECT_EQ(cv::countNonZero(render_depth(world, far, cam)), 0);
}
