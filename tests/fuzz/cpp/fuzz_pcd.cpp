// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// libFuzzer target: the PCD reader kiseki::read_pcd (PCL's reader behind kiseki's header and
// size checks: PCL 1.13 alone crashes on a truncated binary file and on a header without
// fields). std::runtime_error is the documented refusal; anything else, a sanitizer report, a
// hang or a non-finite point returned is a finding.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "kiseki/io/pcd_file.hpp"
#include "temp_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const kiseki::PcdCloud cloud = [&] {
      const kiseki_fuzz::TempInput input(data, size);
      return kiseki::read_pcd(input.path());
    }();
    if (!cloud.points.allFinite()) std::abort();
    if (static_cast<std::size_t>(cloud.points.cols()) + cloud.non_finite != cloud.width * cloud.height) std::abort();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
