// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <string>

namespace octomap {
class OcTree;
}

namespace kiseki {

/// Writes `tree` as an OctoMap binary tree (.bt) file, in the form OctoMap's own
/// writeBinaryConst writes (the same bytes, see octomap_file.cpp), to a temporary file renamed
/// over `path` when complete. The tree is written as it is: callers prune it and make it
/// maximum likelihood first, as OctoMap's writeBinary does. Throws std::runtime_error naming
/// the file when it cannot be written.
void write_octomap_binary(const octomap::OcTree& tree, const std::string& path);

}  // namespace kiseki
