// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
#include "kiseki/io/pcd_file.hpp"

#include "replace_file.hpp"

#include <pcl/console/print.h>
#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace kiseki {

namespace {

/// What a PCD header declares (PCL's format, v0.7).
struct PcdHeader {
  std::vector<std::string> fields, types;
  std::vector<unsigned long long> sizes, counts;
  unsigned long long width = 0, height = 1;
  unsigned long long points = 0;  ///< POINTS, 0 when the header has none
  std::string data;            ///< ascii, binary or binary_compressed
  std::streamoff data_start = 0;
  int xyz[3] = {-1, -1, -1};   ///< the fields x, y, z
};

/// kiseki reads PCD files itself and writes them with PCL. PCL 1.13's reader allocates what a
/// header declares (a COUNT of 10^10 is an allocation of that size), reads past the end of a
/// truncated binary file, crashes on a header without fields, overruns a buffer converting a
/// field of declared SIZE 1 to a float and corrupts its heap on damaged ASCII files (all found
/// by fuzzing it). This reader accepts float x, y, z (SIZE 4 or 8), any other fields of sizes
/// 1, 2, 4, 8 with counts up to 10^6, a point of at most 1 MB, and data the file holds.
PcdHeader read_header(std::ifstream& in, const std::string& path) {
  const auto fail = [&](const std::string& why) {
    throw std::runtime_error(path + ": not a valid PCD file (" + why + ")");
  };
  PcdHeader h;
  std::string line;
  for (int lines = 0; h.data.empty(); ++lines) {
    if (lines > 64 || !std::getline(in, line)) fail("no DATA line in the header");
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key.empty() || key[0] == '#') continue;
    const auto numbers = [&](std::vector<unsigned long long>& out) {
      out.clear();
      for (std::string w; words >> w;) {
        if (w.size() > 12 || w.find_first_not_of("0123456789") != std::string::npos) fail(key + " " + w);
        out.push_back(std::stoull(w));
      }
    };
    std::vector<unsigned long long> one;
    if (key == "FIELDS") {
      h.fields.clear();
      for (std::string w; words >> w;) h.fields.push_back(w);
    } else if (key == "TYPE") {
      h.types.clear();
      for (std::string w; words >> w;) h.types.push_back(w);
    } else if (key == "SIZE") {
      numbers(h.sizes);
    } else if (key == "COUNT") {
      numbers(h.counts);
    } else if (key == "WIDTH" || key == "HEIGHT") {
      numbers(one);
      if (one.size() != 1) fail(key);
      (key == "WIDTH" ? h.width : h.height) = one[0];
    } else if (key == "POINTS") {
      numbers(one);
      if (one.size() != 1 || one[0] == 0) fail(key);
      h.points = one[0];
    } else if (key == "DATA") {
      words >> h.data;
      if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed") fail("DATA " + h.data);
    }
  }
  h.data_start = in.tellg();
  if (h.fields.empty() || h.sizes.size() != h.fields.size() || h.types.size() != h.fields.size()) {
    fail("FIELDS, SIZE and TYPE differ in length");
  }
  if (h.counts.empty()) h.counts.assign(h.fields.size(), 1);
  if (h.counts.size() != h.fields.size()) fail("COUNT differs in length from FIELDS");
  unsigned long long point = 0;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const auto size = h.sizes[i];
    if (size != 1 && size != 2 && size != 4 && size != 8) fail("SIZE " + std::to_string(size));
    if (h.types[i] != "F" && h.types[i] != "I" && h.types[i] != "U") fail("TYPE " + h.types[i]);
    if (h.counts[i] < 1 || h.counts[i] > 1'000'000) fail("COUNT " + std::to_string(h.counts[i]));
    const int k = h.fields[i] == "x" ? 0 : h.fields[i] == "y" ? 1 : h.fields[i] == "z" ? 2 : -1;
    if (k >= 0) {
      if (h.types[i] != "F" || (size != 4 && size != 8)) fail("field " + h.fields[i] + " is not a float");
      if (h.xyz[k] < 0) h.xyz[k] = static_cast<int>(i);
    }
    point += size * h.counts[i];
  }
  if (h.xyz[0] < 0 || h.xyz[1] < 0 || h.xyz[2] < 0) fail("no x, y, z fields");
  if (point > 1'000'000) fail("a point of more than 1 MB");
  if (h.width == 0 || h.height == 0 || h.width > 1'000'000'000ULL || h.height > 1'000'000'000ULL / h.width) {
    fail("WIDTH x HEIGHT");
  }
  if (h.points != 0 && h.points != h.width * h.height) {
    fail("POINTS " + std::to_string(h.points) + " is not WIDTH x HEIGHT, " + std::to_string(h.width * h.height));
  }
  if (h.data_start < 0) fail("no data after the header");
  return h;
}

// Zero bytes that older PCL releases' binary writer left after the data: it sized the file to
// a memory page plus the data (the header shorter than a page), 4 kB or 64 kB pages.
constexpr unsigned long long kPcdPadding = 65536;

double float_at(const unsigned char* p, unsigned long long size) {
  if (size == 8) {
    double v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  float v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

/// PCL reports through its console; kiseki reports through exceptions naming the file.
void quiet_pcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

}  // namespace

PcdCloud read_pcd(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error(path + ": no such PCD file");
  const auto file_size = static_cast<unsigned long long>(std::filesystem::file_size(path, ec));
  std::ifstream in(path, std::ios::binary);
  if (ec || !in) throw std::runtime_error(path + ": cannot open the PCD file");
  const PcdHeader h = read_header(in, path);
  const unsigned long long n = h.width * h.height;
  std::vector<unsigned long long> offset(h.fields.size() + 1, 0), value_index(h.fields.size() + 1, 0);
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    offset[i + 1] = offset[i] + h.sizes[i] * h.counts[i];
    value_index[i + 1] = value_index[i] + h.counts[i];
  }
  const unsigned long long step = offset.back(), bytes = n * step;
  const unsigned long long left = file_size - std::min<unsigned long long>(file_size, h.data_start);
  const auto truncated = [&](const std::string& what) {
    return std::runtime_error(path + ": the PCD file is truncated (" + what + ")");
  };
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(std::min<unsigned long long>(n, left / 2 + 1)));
  std::size_t non_finite = 0;
  const auto keep = [&](const Eigen::Vector3d& p) {
    if (p.allFinite()) {
      points.push_back(p);
    } else {
      ++non_finite;
    }
  };
  if (h.data == "ascii") {
    if (n > left / 2) throw truncated("fewer lines than points");
    std::vector<double> values(value_index.back());
    std::string line;
    for (unsigned long long j = 0; j < n; ++j) {
      if (!std::getline(in, line)) throw truncated("point " + std::to_string(j) + " of " + std::to_string(n));
      const char* c = line.c_str();
      const auto space = [](char ch) { return ch == ' ' || ch == '\t' || ch == '\r'; };
      for (auto& v : values) {
        char* end = nullptr;
        v = std::strtod(c, &end);
        // strtod stops at the first character it cannot read: "3_4" or "3.5abc" would be 3 and
        // 3.5, so a number must end at white space or the line's end
        if (end == c || (*end != '\0' && !space(*end))) {
          throw std::runtime_error(path + ": not a number in point " + std::to_string(j));
        }
        c = end;
      }
      while (space(*c)) ++c;
      if (*c != '\0') {
        throw std::runtime_error(path + ": point " + std::to_string(j) + " has more values than the header's " +
                                 std::to_string(values.size()));
      }
      keep({values[value_index[static_cast<std::size_t>(h.xyz[0])]], values[value_index[static_cast<std::size_t>(h.xyz[1])]],
            values[value_index[static_cast<std::size_t>(h.xyz[2])]]});
    }
    // What follows the declared points may be blank, never more points: a header that declares
    // too few would silently drop the rest of the cloud.
    while (std::getline(in, line)) {
      if (line.find_first_not_of(" \t\r") != std::string::npos) {
        throw std::runtime_error(path + ": the PCD file holds more data lines than its " + std::to_string(n) +
                                 " points (WIDTH x HEIGHT)");
      }
    }
  } else {
    std::vector<unsigned char> data;
    if (h.data == "binary") {
      if (bytes > left) throw truncated(std::to_string(bytes) + " bytes of binary data declared, " + std::to_string(left) + " present");
      data.resize(static_cast<std::size_t>(bytes));
      in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(bytes));
      // More bytes than the points need: the header does not describe the data (text data
      // declared binary, or too few points declared), unless they are zeros of older PCL
      // writers' padding (kPcdPadding).
      if (bytes < left) {
        std::vector<char> rest(static_cast<std::size_t>(std::min<unsigned long long>(left - bytes, kPcdPadding + 1)));
        in.read(rest.data(), static_cast<std::streamsize>(rest.size()));
        const bool padding = left - bytes <= kPcdPadding && std::all_of(rest.begin(), rest.end(), [](char c) { return c == 0; });
        if (!padding) {
          throw std::runtime_error(path + ": not a valid PCD file (" + std::to_string(bytes) +
                                   " bytes of binary data declared, " + std::to_string(left) + " present)");
        }
      }
    } else {
      std::uint32_t sizes[2] = {0, 0};
      in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
      if (!in || left < 8ull + sizes[0] || sizes[1] != bytes || bytes > 256ull * (sizes[0] + 1ull)) {
        throw truncated("compressed data");
      }
      std::vector<unsigned char> packed(sizes[0]);
      in.read(reinterpret_cast<char*>(packed.data()), sizes[0]);
      data.resize(static_cast<std::size_t>(bytes));
      if (!in || pcl::lzfDecompress(packed.data(), sizes[0], data.data(), sizes[1]) != sizes[1]) {
        throw std::runtime_error(path + ": the PCD file's compressed data is corrupt");
      }
    }
    if (!in) throw truncated("binary data");
    // binary: point after point; binary_compressed: field after field (PCL's layout)
    const bool by_field = h.data == "binary_compressed";
    const auto at = [&](int field, unsigned long long j) {
      const auto f = static_cast<std::size_t>(field);
      const unsigned long long pos = by_field ? offset[f] * n + j * h.sizes[f] * h.counts[f] : j * step + offset[f];
      return float_at(data.data() + pos, h.sizes[f]);
    };
    for (unsigned long long j = 0; j < n; ++j) keep({at(h.xyz[0], j), at(h.xyz[1], j), at(h.xyz[2], j)});
  }
  PcdCloud out;
  out.width = static_cast<std::size_t>(h.width);
  out.height = static_cast<std::size_t>(h.height);
  out.non_finite = non_finite;
  out.points.resize(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) out.points.col(static_cast<Eigen::Index>(i)) = points[i];
  return out;
}

void write_pcd(const std::string& path, const Eigen::Matrix3Xd& points) {
  quiet_pcl();
  if (points.cols() == 0) throw std::invalid_argument("write_pcd: no points to write");
  if (!points.allFinite()) throw std::invalid_argument("write_pcd: the points hold NaN or infinity");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.resize(static_cast<std::size_t>(points.cols()));
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    cloud[static_cast<std::size_t>(i)] = pcl::PointXYZ(static_cast<float>(points(0, i)), static_cast<float>(points(1, i)),
                                                       static_cast<float>(points(2, i)));
  }
  const std::string partial = path + ".partial";
  int result = -1;
  try {
    result = pcl::io::savePCDFileBinary(partial, cloud);
  } catch (const std::exception& e) {
    std::remove(partial.c_str());
    throw std::runtime_error(path + ": cannot write the PCD file (" + e.what() + ")");
  }
  io_detail::replace_with_partial(partial, path, result >= 0, "the PCD file");
}

}  // namespace kiseki
