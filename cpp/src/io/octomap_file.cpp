// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/io/octomap_file.hpp"

#include "replace_file.hpp"

#include <octomap/OcTree.h>

#include <fstream>
#include <string>

namespace kiseki {

// OctoMap's writeBinaryConst writes this header and then the nodes (writeBinaryData), and on
// success prints " done." to standard error: Debian builds the library with its debug output
// on, so every .bt a user wrote came with that line. The header is written here in the same
// words and number format (an ostream's default, as OctoMap's own), and the nodes by OctoMap's
// writeBinaryData, which prints nothing: the file is byte for byte OctoMap's (tested).
void write_octomap_binary(const octomap::OcTree& tree, const std::string& path) {
  const std::string partial = path + ".partial";
  bool ok = false;
  {
    std::ofstream out(partial, std::ios::binary);
    if (out) {
      out << "# Octomap OcTree binary file\n"
          << "# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
          << "id " << tree.getTreeType() << '\n'
          << "size " << tree.size() << '\n'
          << "res " << tree.getResolution() << '\n'
          << "data\n";
      tree.writeBinaryData(out);
      ok = out.flush().good();
    }
  }
  io_detail::replace_with_partial(partial, path, ok, "the OctoMap file");
}

}  // namespace kiseki
