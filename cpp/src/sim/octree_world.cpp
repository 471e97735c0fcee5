// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/sim/octree_world.hpp"

#include "kiseki/io/octomap_file.hpp"

#include <octomap/OcTree.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace kiseki {

namespace {

/// Runs `read` with the process' standard error sent to a temporary file and returns what was
/// written there: OctoMap reports a damaged file on stderr (fprintf and std::cerr), not to its
/// caller, so a user saw its lines above kiseki's own one-line error (and one more line on
/// every read). The redirection is the process': one read at a time holds it (a second one
/// would restore stderr to the first's file), and what another thread writes to stderr during a
/// read (milliseconds) lands in the file too.
template <class Read>
std::string with_stderr_captured(Read&& read) {
  static std::mutex one_at_a_time;
  const std::lock_guard<std::mutex> lock(one_at_a_time);
  std::fflush(stderr);
  std::cerr.flush();
  std::FILE* sink = std::tmpfile();
  // the saved stderr is not inherited by a program the read might start (close on exec)
  const int saved = sink == nullptr ? -1 : ::fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 0);
  if (saved < 0 || ::dup2(::fileno(sink), STDERR_FILENO) < 0) {  // cannot redirect: read as is
    if (saved >= 0) ::close(saved);
    if (sink != nullptr) std::fclose(sink);
    read();
    return {};
  }
  const auto restore = [&] {
    std::fflush(stderr);
    std::cerr.flush();
    ::dup2(saved, STDERR_FILENO);
    ::close(saved);
  };
  try {
    read();
  } catch (...) {
    restore();
    std::fclose(sink);
    throw;
  }
  restore();
  std::string text;
  std::rewind(sink);
  char chunk[512];
  for (std::size_t n = 0; text.size() < 4096 && (n = std::fread(chunk, 1, sizeof chunk, sink)) > 0;) {
    text.append(chunk, n);
  }
  std::fclose(sink);
  return text;
}

/// OctoMap's lines that report a problem ("ERROR: ..." or "WARNING: ..."); its other line,
/// "Reading binary octree type OcTree", is printed on every read.
std::vector<std::string> problems(const std::string& text) {
  std::vector<std::string> found;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string line = text.substr(at, end - at);
    if (line.rfind("ERROR: ", 0) == 0 || line.rfind("WARNING: ", 0) == 0) found.push_back(line);
    at = end + 1;
  }
  return found;
}

}  // namespace

OctreeWorld::OctreeWorld(std::unique_ptr<octomap::OcTree> tree) : tree_(std::move(tree)) {}
OctreeWorld::OctreeWorld(OctreeWorld&&) noexcept = default;
OctreeWorld& OctreeWorld::operator=(OctreeWorld&&) noexcept = default;
OctreeWorld::~OctreeWorld() = default;

OctreeWorld OctreeWorld::read_binary(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open OctoMap file");
  std::string header;
  std::getline(in, header);
  if (header.rfind("# Octomap OcTree binary file", 0) != 0) {
    throw std::runtime_error(path + ": not an OctoMap binary tree (.bt) file");
  }
  // the tree's kind: OctoMap reads another kind's nodes (a ColorOcTree's colours) as OcTree
  // nodes, or a made-up id, without a word
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);  // token by token, as OctoMap reads its header
    std::string key, value;
    words >> key >> value;
    if (key == "data") break;
    if (key == "id" && value != "OcTree") {
      throw std::runtime_error(path + ": an OctoMap tree of kind '" + value + "', not OcTree (occupancy only)");
    }
  }
  in.clear();
  in.seekg(0);
  auto tree = std::make_unique<octomap::OcTree>(0.1);
  bool read = false;
  const std::string said = with_stderr_captured([&] { read = tree->readBinary(in); });
  const std::vector<std::string> reported = problems(said);
  if (!read || tree->size() == 0) {
    std::string why;
    for (const std::string& line : reported) {
      if (why.empty() && line.rfind("ERROR: ", 0) == 0) why = " (OctoMap: " + line.substr(7) + ")";
    }
    throw std::runtime_error(path + ": corrupt or truncated OctoMap binary file" + why);
  }
  // OctoMap stops after the tree: white space may follow (a line end added by an editor), not
  // data (a damaged or concatenated file)
  std::size_t after = 0, data_after = 0;
  for (int c = in.get(); c != std::ifstream::traits_type::eof(); c = in.get()) {
    ++after;
    data_after += !std::isspace(c);
  }
  if (data_after > 0) {
    throw std::runtime_error(path + ": " + std::to_string(after) +
                             " bytes after the OctoMap tree (a damaged or concatenated file)");
  }
  for (const std::string& line : reported) std::cerr << line << '\n';  // read, with warnings
  std::cerr.flush();
  return OctreeWorld(std::move(tree));
}

OctreeWorld OctreeWorld::from_boxes(const BoxWorld& world, double resolution) {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw std::invalid_argument("OctreeWorld: resolution must be positive");
  }
  auto tree = std::make_unique<octomap::OcTree>(resolution);
  // A voxel is occupied when its centre lies in the box grown by half a voxel: exactly the
  // voxels a box overlaps when it is axis aligned, a slight over-fill when it is rotated, and
  // never a hole in a thin slab.
  const Eigen::Vector3d grow = Eigen::Vector3d::Constant(0.5 * resolution);
  for (Box b : world.boxes()) {
    b.half_size += grow;
    const Eigen::AlignedBox3d bb = b.aabb();
    octomap::OcTreeKey lo, hi;
    if (!tree->coordToKeyChecked(bb.min().x(), bb.min().y(), bb.min().z(), lo) ||
        !tree->coordToKeyChecked(bb.max().x(), bb.max().y(), bb.max().z(), hi)) {
      throw std::invalid_argument("OctreeWorld: a box lies outside OctoMap's addressable range");
    }
    for (unsigned kx = lo[0]; kx <= hi[0]; ++kx)
      for (unsigned ky = lo[1]; ky <= hi[1]; ++ky)
        for (unsigned kz = lo[2]; kz <= hi[2]; ++kz) {
          const octomap::OcTreeKey key(kx, ky, kz);
          const octomap::point3d c = tree->keyToCoord(key);
          if (b.contains({c.x(), c.y(), c.z()})) tree->updateNode(key, true, true);
        }
  }
  tree->updateInnerOccupancy();
  return OctreeWorld(std::move(tree));
}

double OctreeWorld::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         double max_range) const {
  if (!origin.allFinite() || !direction.allFinite() || std::abs(direction.norm() - 1.0) > 1e-6) {
    throw std::invalid_argument("OctreeWorld::cast: origin must be finite, direction a unit vector");
  }
  octomap::point3d end;
  const octomap::point3d o(origin.x(), origin.y(), origin.z());
  const octomap::point3d d(direction.x(), direction.y(), direction.z());
  if (!tree_->castRay(o, d, end, true, max_range)) return max_range;
  // castRay returns the hit voxel's centre: report the distance to its entry face along the ray.
  const double h = 0.5 * tree_->getResolution();
  const Eigen::Vector3d c(end.x(), end.y(), end.z());
  double t0 = 0.0, t1 = max_range;
  for (int k = 0; k < 3; ++k) {
    if (direction[k] == 0.0) continue;
    double ta = (c[k] - h - origin[k]) / direction[k], tb = (c[k] + h - origin[k]) / direction[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return std::min(t0, max_range);
}

Eigen::AlignedBox3d OctreeWorld::bounds() const {
  double x0, y0, z0, x1, y1, z1;
  tree_->getMetricMin(x0, y0, z0);
  tree_->getMetricMax(x1, y1, z1);
  return {Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)};
}

double OctreeWorld::resolution() const { return tree_->getResolution(); }

std::size_t OctreeWorld::occupied_leaves() const {
  std::size_t n = 0;
  for (auto it = tree_->begin_leafs(); it != tree_->end_leafs(); ++it) n += tree_->isNodeOccupied(*it);
  return n;
}

void OctreeWorld::write_binary(const std::string& path) const {
  tree_->toMaxLikelihood();  // as OctoMap's writeBinary: the world's voxels are free or occupied already
  tree_->prune();
  write_octomap_binary(*tree_, path);
}

void OctreeWorld::rasterize_band(double z_min, double z_max, OccupancyGrid& grid) const {
  if (!(z_max > z_min)) throw std::invalid_argument("rasterize_band: need z_max > z_min");
  grid.cells().setTo(kUnknown);
  // The leaves in the band under the grid (its corners' box: the grid may be rotated), queried
  // by keys clamped to OctoMap's addressable range: the coordinate form of begin_leafs_bbx
  // hands out an iterator on a null tree when a corner lies outside that range, as the upper
  // face of a tree's last voxel does (a fuzzed .bt crashed here).
  const double w = grid.width(), h = grid.height();
  Eigen::Vector2d lo = grid.grid_to_world({0.0, 0.0}), hi = lo;
  for (const Eigen::Vector2d& corner :
       {grid.grid_to_world({w, 0.0}), grid.grid_to_world({0.0, h}), grid.grid_to_world({w, h})}) {
    lo = lo.cwiseMin(corner);
    hi = hi.cwiseMax(corner);
  }
  const auto clamped_key = [this](double x, double y, double z) {
    octomap::OcTreeKey key;
    const double coords[3] = {x, y, z};
    for (int i = 0; i < 3; ++i) {
      if (!tree_->coordToKeyChecked(coords[i], key[i])) {
        key[i] = coords[i] < 0.0 ? 0 : std::numeric_limits<octomap::key_type>::max();
      }
    }
    return key;
  };
  const octomap::OcTreeKey lo_key = clamped_key(lo.x(), lo.y(), z_min);
  const octomap::OcTreeKey hi_key = clamped_key(hi.x(), hi.y(), z_max);
  for (auto it = tree_->begin_leafs_bbx(lo_key, hi_key); it != tree_->end_leafs_bbx(); ++it) {
    const double half = 0.5 * it.getSize();
    const bool occ = tree_->isNodeOccupied(*it);
    // A leaf may be a large pruned node: mark every grid cell its footprint covers, walking
    // its sample lattice only where it meets the grid (a step of margin for rounding).
    const double step = std::min(grid.resolution(), it.getSize()) * 0.5;
    const auto range = [&](double centre, double low, double high) {
      const double first = centre - half + 0.5 * step;
      const double skip = std::max(0.0, std::floor((low - step - first) / step));
      return std::make_pair(first + skip * step, std::min(centre + half, high + step));
    };
    const auto [x0, x1] = range(it.getX(), lo.x(), hi.x());
    const auto [y0, y1] = range(it.getY(), lo.y(), hi.y());
    for (double x = x0; x < x1; x += step)
      for (double y = y0; y < y1; y += step) {
        const CellIndex c = grid.world_to_cell({x, y});
        if (!grid.contains(c)) continue;
        std::int8_t& v = grid.cells().ptr<std::int8_t>(c.y)[c.x];
        if (occ) v = kOccupied;
        else if (v == kUnknown) v = kFree;
      }
  }
}

}  // namespace kiseki
