// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/io/octomap_file.hpp"

#include <octomap/OcTree.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

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
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(path + ": cannot write the OctoMap file");
  }
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(path + ": cannot write the OctoMap file (" + ec.message() + ")");
  }
}

}  // namespace kiseki
