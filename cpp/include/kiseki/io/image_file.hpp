// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#pragma once

#include <opencv2/core/mat.hpp>
#include <string>

// Image files through OpenCV's codecs. A library of its own (kiseki_image_io), not part of
// kiseki_core: Debian's OpenCV codecs load GDAL and about 140 other libraries (0.1 s), which a
// process that reads no image should not pay for.

namespace kiseki {

/// Reads an image file as stored (cv::IMREAD_UNCHANGED). Throws std::runtime_error naming the
/// file when it does not exist or cannot be decoded.
cv::Mat read_image(const std::string& path);
/// Writes an image (PGM, PNG, ... by extension). Throws std::runtime_error on failure.
void write_image(const std::string& path, const cv::Mat& image);

}  // namespace kiseki
