// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/versions.hpp"

#include <cblas.h>

#include <Eigen/Core>
#include <octomap/OcTree.h>
#include <opencv2/core/version.hpp>
#include <pcl/pcl_config.h>

#include <sstream>

namespace kiseki {

namespace {

/// OpenBLAS' version and the kernels it runs on, e.g. "0.3.21, SkylakeX kernels": the last bits
/// of the Gaussian processes' results depend on the kernels.
std::string openblas() {
  std::istringstream config(openblas_get_config());  // "OpenBLAS 0.3.21 DYNAMIC_ARCH ..."
  std::string name, version;
  config >> name >> version;
  return version + ", " + openblas_get_corename() + " kernels";
}

}  // namespace

std::map<std::string, std::string> library_versions() {
  octomap::OcTree probe(0.1);  // links liboctomap: proves the library is usable, not only its headers
  const std::string octomap_version = probe.getTreeType() == "OcTree" ? KISEKI_OCTOMAP_VERSION : "broken";
  return {
      {"kiseki", KISEKI_VERSION},
      {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
                    "." + std::to_string(EIGEN_MINOR_VERSION)},
      {"opencv", CV_VERSION},
      {"pcl", PCL_VERSION_PRETTY},
      {"octomap", octomap_version},
      {"openblas", openblas()},
  };
}

}  // namespace kiseki
