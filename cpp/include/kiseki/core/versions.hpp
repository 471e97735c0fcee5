// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <map>
#include <string>

namespace kiseki {

/// kiseki's version and the versions of the C++ libraries it was built against (keys: kiseki,
/// eigen, opencv, pcl, octomap), and of the OpenBLAS it runs on with the kernels OpenBLAS chose
/// when it was loaded (key openblas, e.g. "0.3.21, SkylakeX kernels").
std::map<std::string, std::string> library_versions();

}  // namespace kiseki
