// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/io/image_file.hpp"

#include <cctype>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace kiseki {

cv::Mat read_image(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {  // a folder opens, and tellg says 2^63
    throw std::runtime_error(path + ": cannot open image file (not a regular file)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in.good()) throw std::runtime_error(path + ": cannot open image file");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0);
  if (size < 0) throw std::runtime_error(path + ": cannot read image file");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) throw std::runtime_error(path + ": cannot read image file");
  if (bytes.empty()) throw std::runtime_error(path + ": cannot decode image (an empty file)");
  // A text Netpbm image (P1, P2, P3) may end with its last value, without a line end after it
  // (the format separates values by white space); OpenCV's decoder then fails on the missing
  // delimiter ("Unexpected end of input stream") and prints so. One line end is added here.
  const bool text_netpbm = bytes.size() > 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '3';
  if (text_netpbm && !std::isspace(static_cast<unsigned char>(bytes.back()))) bytes.push_back('\n');
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot decode image (" + e.what() + ")");
  }
  if (image.empty()) throw std::runtime_error(path + ": cannot decode image");
  return image;
}

void write_image(const std::string& path, const cv::Mat& image) {
  // Encoded in memory, then written with every step checked: cv::imwrite reports success for a
  // file that a full disk has cut short. The error ends with the system's reason.
  const auto dot = path.find_last_of('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) {
    throw std::runtime_error(path + ": cannot write image (no file extension to choose a format by)");
  }
  std::vector<std::uint8_t> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(path.substr(dot), image, bytes);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": cannot write image (" + e.what() + ")");
  }
  if (!ok) throw std::runtime_error(path + ": cannot write image (encoding failed)");
  errno = 0;
  std::FILE* out = std::fopen(path.c_str(), "wb");
  if (out == nullptr) throw std::runtime_error(path + ": cannot write image: " + std::strerror(errno));
  const std::size_t written = std::fwrite(bytes.data(), 1, bytes.size(), out);
  int error = written == bytes.size() ? 0 : errno;
  if (std::fclose(out) != 0 && error == 0) error = errno;  // a full disk shows at the flush
  if (written != bytes.size() && error == 0) error = EIO;
  if (error != 0) throw std::runtime_error(path + ": cannot write image: " + std::strerror(error));
}

}  // namespace kiseki
