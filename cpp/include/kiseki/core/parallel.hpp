// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

#include "kiseki/core/threads.hpp"

// Built with OpenMP (the core's sources are compiled with -fopenmp); without it the loop below
// runs its chunks one after another on the calling thread, with the same results.

namespace kiseki {

/// Runs body(begin, end) over [0, n) split into contiguous chunks of at least `min_chunk` items,
/// on up to `threads` threads of OpenMP's pool (started once, so a parallel loop costs
/// microseconds; small inputs stay on the calling thread). The chunks depend only on n, threads
/// and min_chunk, and are disjoint, so a body that writes only to its own items gives the same
/// result for any thread count. The first exception thrown by a chunk is rethrown on the
/// calling thread after every chunk has finished.
template <typename Body>
void parallel_for(std::size_t n, int threads, Body&& body, std::size_t min_chunk = 256) {
  if (n == 0) return;
  const std::size_t by_size = std::max<std::size_t>(1, n / std::max<std::size_t>(1, min_chunk));
  const std::size_t asked = static_cast<std::size_t>(std::min(resolve_threads(threads), kMaxThreads));
  const std::size_t t = std::min<std::size_t>(asked, by_size);
  if (t <= 1) {
    body(std::size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(t);
  const std::size_t chunk = (n + t - 1) / t;
  const auto count = static_cast<long long>(t);
#pragma omp parallel for schedule(static, 1) num_threads(static_cast<int>(t))
  for (long long k = 0; k < count; ++k) {
    const std::size_t begin = std::min(n, static_cast<std::size_t>(k) * chunk), end = std::min(n, begin + chunk);
    try {
      if (begin < end) body(begin, end);
    } catch (...) {
      errors[static_cast<std::size_t>(k)] = std::current_exception();
    }
  }
  for (auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace kiseki
