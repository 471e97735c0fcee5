// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace kiseki::io_detail {

/// Ends a write to `partial` (the file beside `path` the writer filled): renamed over `path`
/// when `written`, else removed, so that `path` holds the whole new file or what it held
/// before. Throws std::runtime_error "PATH: cannot write WHAT" (with the system's reason for a
/// failed rename) when the file is not in place.
inline void replace_with_partial(const std::string& partial, const std::string& path, bool written,
                                 const std::string& what) {
  std::error_code ec;
  if (!written) {
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(path + ": cannot write " + what);
  }
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    throw std::runtime_error(path + ": cannot write " + what + " (" + ec.message() + ")");
  }
}

}  // namespace kiseki::io_detail
