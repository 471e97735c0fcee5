// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <string>

#include "kiseki/grid/occupancy_grid.hpp"

namespace kiseki {

/// How image pixels map to cell values (the ROS map_server "mode" field).
enum class MapMode { Trinary, Scale, Raw };

/// The interpretation fields of a ROS map YAML file. Defaults follow the ROS 1 map_saver
/// (free_thresh 0.196), so that the 205-grey of unknown cells reloads as unknown.
struct MapImageParams {
  MapMode mode = MapMode::Trinary;
  bool negate = false;
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
};

/// Throws std::invalid_argument when thresholds are outside [0, 1] or free > occupied.
void validate(const MapImageParams& params);

/// Converts a map image to cells with nav2 map_server's rules: shade = mean of the colour
/// channels (plus opacity in trinary mode when there is an alpha channel), occ = 1 - shade
/// (shade when negate); trinary: occ > occupied_thresh -> 100, occ < free_thresh -> 0, else -1;
/// scale: like trinary but in-between values scale linearly to 0..100 and non-opaque pixels are
/// unknown; raw: the 0..255 pixel value itself when it lies in 0..100, else unknown.
/// Image rows are top-down, so image row r becomes grid row height-1-r. Accepts 8- or 16-bit
/// images with 1 to 4 channels (OpenCV channel order).
OccupancyGrid occupancy_from_image(const cv::Mat& image, double resolution, const Pose2& origin,
                                   const MapImageParams& params);

/// Converts cells to an image with nav2 map_saver's rules: trinary writes 254 (free, value <=
/// free_thresh*100), 0 (occupied, value >= occupied_thresh*100) and 205 (everything else);
/// scale writes grey (100 - value)/100 with unknown cells fully transparent (4 channels);
/// raw writes the value itself and 255 for unknown. negate inverts trinary and scale shades.
cv::Mat image_from_occupancy(const OccupancyGrid& grid, const MapImageParams& params);

}  // namespace kiseki
