// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/core/versions.hpp"

#include <Eigen/Core>
#include <octomap/OcTree.h>
#include <opencv2/core/version.hpp>
#include <pcl/pcl_config.h>

namespace kiseki {

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
  };
}

}  // namespace kiseki
