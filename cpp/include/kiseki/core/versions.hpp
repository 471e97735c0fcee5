// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <map>
#include <string>

namespace kiseki {

/// kiseki's version and the versions of the C++ libraries it was built against
/// (keys: kiseki, eigen, opencv, pcl, octomap).
std::map<std::string, std::string> library_versions();

}  // namespace kiseki
