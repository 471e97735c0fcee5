// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/grid/map_image.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace kiseki {
namespace {

// Pixel channels scaled to [0, 1], in OpenCV order (B, G, R, A) or (grey, A).
struct PixelReader {
  const cv::Mat& image;
  double scale;
  int channels;
  double get(int row, int col, int ch) const {
    if (image.depth() == CV_8U) return image.ptr<std::uint8_t>(row)[col * channels + ch] * scale;
    return image.ptr<std::uint16_t>(row)[col * channels + ch] * scale;
  }
};

std::int8_t cell_from_pixel(const PixelReader& px, int row, int col, const MapImageParams& p) {
  const int n = px.channels;
  const bool has_alpha = n == 2 || n == 4;
  const int colour = has_alpha ? n - 1 : n;
  double sum = 0.0;
  for (int c = 0; c < colour; ++c) sum += px.get(row, col, c);
  const double opacity = has_alpha ? px.get(row, col, n - 1) : 1.0;
  int count = colour;
  if (p.mode == MapMode::Trinary && has_alpha) {
    sum += opacity;  // nav2 averages opacity in with the colours in trinary mode
    ++count;
  }
  const double shade = sum / count;
  if (p.mode == MapMode::Raw) {
    const double v = std::round(shade * 255.0);
    return (v >= 0.0 && v <= 100.0) ? static_cast<std::int8_t>(v) : kUnknown;
  }
  const double occ = p.negate ? shade : 1.0 - shade;
  if (p.mode == MapMode::Scale && opacity < 1.0) return kUnknown;
  if (p.occupied_thresh < occ) return kOccupied;
  if (occ < p.free_thresh) return kFree;
  // Trinary, or scale with equal thresholds and occ exactly on them (0/0: a fuzzed map's NaN
  // cast to int8, undefined behaviour): neither free nor occupied.
  if (p.mode == MapMode::Trinary || !(p.occupied_thresh > p.free_thresh)) return kUnknown;
  return static_cast<std::int8_t>(
      std::rint((occ - p.free_thresh) / (p.occupied_thresh - p.free_thresh) * 100.0));
}

}  // namespace

void validate(const MapImageParams& p) {
  const auto in_unit = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 1.0; };
  if (!in_unit(p.occupied_thresh) || !in_unit(p.free_thresh)) {
    throw std::invalid_argument("map image: occupied_thresh and free_thresh must lie in [0, 1]");
  }
  if (p.free_thresh > p.occupied_thresh) {
    throw std::invalid_argument("map image: free_thresh must not exceed occupied_thresh");
  }
}

OccupancyGrid occupancy_from_image(const cv::Mat& image, double resolution, const Pose2& origin,
                                   const MapImageParams& params) {
  validate(params);
  if (image.empty() || image.dims != 2) throw std::invalid_argument("map image: image is empty");
  if (image.depth() != CV_8U && image.depth() != CV_16U) {
    throw std::invalid_argument("map image: only 8-bit and 16-bit images are supported");
  }
  if (image.channels() < 1 || image.channels() > 4) {
    throw std::invalid_argument("map image: images must have 1 to 4 channels");
  }
  OccupancyGrid grid(image.cols, image.rows, resolution, origin, kUnknown);
  const PixelReader px{image, image.depth() == CV_8U ? 1.0 / 255.0 : 1.0 / 65535.0,
                       image.channels()};
  for (int r = 0; r < image.rows; ++r) {
    auto* out = grid.cells().ptr<std::int8_t>(image.rows - 1 - r);
    for (int c = 0; c < image.cols; ++c) out[c] = cell_from_pixel(px, r, c, params);
  }
  return grid;
}

cv::Mat image_from_occupancy(const OccupancyGrid& grid, const MapImageParams& params) {
  validate(params);
  const int rows = grid.height(), cols = grid.width();
  const int free_max = static_cast<int>(std::rint(params.free_thresh * 100.0));
  const int occ_min = static_cast<int>(std::rint(params.occupied_thresh * 100.0));
  const bool scale = params.mode == MapMode::Scale;
  cv::Mat image(rows, cols, scale ? CV_8UC4 : CV_8UC1);
  for (int r = 0; r < rows; ++r) {
    const auto* in = grid.cells().ptr<std::int8_t>(rows - 1 - r);
    auto* out = image.ptr<std::uint8_t>(r);
    for (int c = 0; c < cols; ++c) {
      const int v = in[c];
      const bool known = v >= 0 && v <= 100;
      if (params.mode == MapMode::Raw) {
        out[c] = known ? static_cast<std::uint8_t>(v) : 255;
      } else if (params.mode == MapMode::Trinary) {
        int shade = 205;
        if (known && v <= free_max) shade = 254;
        else if (known && v >= occ_min) shade = 0;
        out[c] = static_cast<std::uint8_t>(params.negate ? 255 - shade : shade);
      } else {
        int shade = known ? static_cast<int>(std::rint((100 - v) * 2.55)) : 128;
        if (params.negate) shade = 255 - shade;
        for (int k = 0; k < 3; ++k) out[4 * c + k] = static_cast<std::uint8_t>(shade);
        out[4 * c + 3] = known ? 255 : 0;
      }
    }
  }
  return image;
}

}  // namespace kiseki
