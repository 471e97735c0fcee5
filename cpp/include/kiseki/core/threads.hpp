// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <stdexcept>
#include <string>
#include <thread>

namespace kiseki {

/// The most threads a request may ask for (each starts a thread of OpenMP's pool); bound as
/// `kiseki._core.MAX_THREADS`, the limit of the Python configs and options.
inline constexpr int kMaxThreads = 1024;

/// Throws std::invalid_argument naming `who` unless 0 <= threads <= kMaxThreads.
inline void check_threads(int threads, const char* who) {
  if (threads < 0 || threads > kMaxThreads) {
    throw std::invalid_argument(std::string(who) + ": threads must be in 0.." + std::to_string(kMaxThreads) +
                                " (0 = every core)");
  }
}

/// The number of threads a request for `threads` means: 0 = every hardware thread.
inline int resolve_threads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

}  // namespace kiseki
