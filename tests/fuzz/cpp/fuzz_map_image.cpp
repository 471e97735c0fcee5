// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// libFuzzer target: the map-image decoder of the ROS map reader, as kiseki.map_io.load_map
// calls it: kiseki::read_image (OpenCV's imread on a file) then kiseki::occupancy_from_image.
// The first input byte picks the YAML fields (mode, negate, thresholds); the rest is the image
// file. std::runtime_error (undecodable file) and std::invalid_argument (refused image) are
// the documented refusals; anything else, a sanitizer report or a cell outside -1..100 is a
// finding.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "kiseki/grid/map_image.hpp"
#include "kiseki/io/image_file.hpp"
#include "temp_input.hpp"

namespace {

kiseki::MapImageParams params_from(std::uint8_t byte) {
  static constexpr double kThresholds[4][2] = {{0.65, 0.196}, {0.65, 0.65}, {1.0, 0.0}, {0.0, 0.0}};
  kiseki::MapImageParams p;
  p.mode = static_cast<kiseki::MapMode>(byte % 3);
  p.negate = (byte / 3) % 2 == 1;
  p.occupied_thresh = kThresholds[(byte / 6) % 4][0];
  p.free_thresh = kThresholds[(byte / 6) % 4][1];
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  cv::Mat image;
  try {
    const kiseki_fuzz::TempInput input(data + 1, size - 1);  // removed after the read
    image = kiseki::read_image(input.path());
  } catch (const std::runtime_error&) {
    return 0;
  }
  if (static_cast<double>(image.total()) * image.elemSize() > 64.0 * 1024 * 1024) return 0;
  try {
    const kiseki::OccupancyGrid grid =
        kiseki::occupancy_from_image(image, 0.05, kiseki::Pose2{}, params_from(data[0]));
    if (grid.width() != image.cols || grid.height() != image.rows) std::abort();
    for (int r = 0; r < grid.height(); ++r) {
      const auto* row = grid.cells().ptr<std::int8_t>(r);
      for (int c = 0; c < grid.width(); ++c) {
        if (row[c] < -1 || row[c] > 100) std::abort();
      }
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
