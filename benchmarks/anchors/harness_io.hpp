// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// The input and output of the side-by-side harnesses (benchmarks/bench_anchors.py writes the
// input and reads the output; benchmarks/anchors_harness.py holds the same layout in Python).
// Each harness (nav2_harness, beluga_harness, kiseki_harness) is a program of its own that
// includes only this file and the library it drives.
//
// Input file, little-endian:
//   8 bytes  magic "KANCHOR1"
//   int32    width, height (cells), scans, beams
//   float64  resolution (m), origin x, origin y (m, the corner of cell 0), max range (m)
//   float64  kParameterCount parameters (Parameter below)
//   int8     cells[height][width]   0 free, 100 occupied, -1 unknown (row 0 at the origin)
//   float64  angles[beams]          bearing of each beam in the laser frame (rad)
//   float32  ranges[scans][beams]   NaN: no valid reading
//   float64  odometry[scans][3]     x, y, theta of the laser
// Output file: float64 [scans][4]: the estimate x, y, theta after each update and the wall
// time in seconds of the library's update calls for that scan.
#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace harness {

enum Parameter {
  kZHit,
  kZRand,
  kSigmaHit,
  kLikelihoodMaxDist,  // nav2's laser_likelihood_max_dist
  kZShort,
  kZMax,
  kLambdaShort,
  kAlpha1,
  kAlpha2,
  kAlpha3,
  kAlpha4,
  kInitialX,
  kInitialY,
  kInitialTheta,
  kInitialSdX,
  kInitialSdY,
  kInitialSdTheta,
  kParameterCount
};

constexpr char kMagic[9] = "KANCHOR1";

struct Input {
  std::int32_t width = 0, height = 0, scans = 0, beams = 0;
  double resolution = 0.0, origin_x = 0.0, origin_y = 0.0, max_range = 0.0;
  std::array<double, kParameterCount> parameters{};
  std::vector<std::int8_t> cells;
  std::vector<double> angles;
  std::vector<float> ranges;
  std::vector<double> odometry;

  double operator[](Parameter p) const { return parameters[p]; }
  const float* scan(int k) const { return ranges.data() + static_cast<std::size_t>(k) * beams; }
  const double* odom(int k) const { return odometry.data() + 3 * static_cast<std::size_t>(k); }
};

template <class T>
void read_into(std::ifstream& in, T* data, std::size_t count, const char* what) {
  in.read(reinterpret_cast<char*>(data), static_cast<std::streamsize>(sizeof(T) * count));
  if (!in) throw std::runtime_error(std::string("input file ends inside the ") + what);
}

template <class T>
void write_from(std::ofstream& out, const T* data, std::size_t count) {
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(sizeof(T) * count));
}

inline Input read_input(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open the input file " + path);
  char magic[8];
  read_into(in, magic, 8, "header");
  if (std::memcmp(magic, kMagic, 8) != 0) throw std::runtime_error(path + " is not a harness input");
  Input input;
  std::int32_t sizes[4];
  read_into(in, sizes, 4, "header");
  input.width = sizes[0], input.height = sizes[1], input.scans = sizes[2], input.beams = sizes[3];
  if (input.width < 1 || input.height < 1 || input.scans < 1 || input.beams < 1)
    throw std::runtime_error("input: width, height, scans and beams must be >= 1");
  double geometry[4];
  read_into(in, geometry, 4, "header");
  input.resolution = geometry[0], input.origin_x = geometry[1], input.origin_y = geometry[2];
  input.max_range = geometry[3];
  if (!(input.resolution > 0.0) || !(input.max_range > 0.0))
    throw std::runtime_error("input: resolution and max range must be > 0");
  read_into(in, input.parameters.data(), kParameterCount, "parameters");
  input.cells.resize(static_cast<std::size_t>(input.width) * input.height);
  read_into(in, input.cells.data(), input.cells.size(), "cells");
  input.angles.resize(input.beams);
  read_into(in, input.angles.data(), input.angles.size(), "angles");
  input.ranges.resize(static_cast<std::size_t>(input.scans) * input.beams);
  read_into(in, input.ranges.data(), input.ranges.size(), "ranges");
  input.odometry.resize(3 * static_cast<std::size_t>(input.scans));
  read_into(in, input.odometry.data(), input.odometry.size(), "odometry");
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error("input file is longer than its header says");
  return input;
}

/// The same layout back (the round trip of the tests).
inline void write_input(const Input& input, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.write(kMagic, 8);
  const std::int32_t sizes[4] = {input.width, input.height, input.scans, input.beams};
  write_from(out, sizes, 4);
  const double geometry[4] = {input.resolution, input.origin_x, input.origin_y, input.max_range};
  write_from(out, geometry, 4);
  write_from(out, input.parameters.data(), kParameterCount);
  write_from(out, input.cells.data(), input.cells.size());
  write_from(out, input.angles.data(), input.angles.size());
  write_from(out, input.ranges.data(), input.ranges.size());
  write_from(out, input.odometry.data(), input.odometry.size());
}

/// One run: the input, what to run it with, and where the estimates go.
struct Run {
  Input input;
  std::string output;
  long particles = 0;
  std::uint64_t seed = 0;
  int threads = 1;
  std::string model = "likelihood-field";  // or beam
  std::string combination = "nav2";        // or product (kiseki only)
};

inline long parse_integer(const std::string& name, const char* text, long low) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || value < low)
    throw std::runtime_error(name + " must be an integer >= " + std::to_string(low) + ", got " + text);
  return value;
}

/// Usage: HARNESS INPUT OUTPUT --particles N --seed S [--threads T] [--model M]
///        [--combination C];  or HARNESS INPUT --echo COPY (writes the input back).
/// Returns false when the call was an echo (done here).
inline bool parse_run(int argc, char** argv, Run& run) {
  if (argc == 4 && std::string(argv[2]) == "--echo") {
    write_input(read_input(argv[1]), argv[3]);
    return false;
  }
  if (argc < 3) throw std::runtime_error("usage: harness INPUT OUTPUT --particles N --seed S ...");
  run.input = read_input(argv[1]);
  run.output = argv[2];
  for (int i = 3; i < argc; i += 2) {
    const std::string flag = argv[i];
    if (i + 1 >= argc) throw std::runtime_error(flag + " needs a value");
    const char* value = argv[i + 1];
    if (flag == "--particles") {
      run.particles = parse_integer(flag, value, 1);
    } else if (flag == "--seed") {
      run.seed = static_cast<std::uint64_t>(std::strtoull(value, nullptr, 10));
    } else if (flag == "--threads") {
      run.threads = static_cast<int>(parse_integer(flag, value, 1));
    } else if (flag == "--model") {
      run.model = value;
      if (run.model != "likelihood-field" && run.model != "beam")
        throw std::runtime_error("--model must be likelihood-field or beam, got " + run.model);
    } else if (flag == "--combination") {
      run.combination = value;
      if (run.combination != "nav2" && run.combination != "product")
        throw std::runtime_error("--combination must be nav2 or product, got " + run.combination);
    } else {
      throw std::runtime_error("unknown option " + flag);
    }
  }
  if (run.particles < 1) throw std::runtime_error("--particles is required");
  return true;
}

/// Per scan: the estimate (x, y, theta) and the seconds the update calls took.
struct Step {
  double x, y, theta, seconds;
};

inline void write_output(const std::vector<Step>& steps, const std::string& path) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path);
  write_from(out, steps.data(), steps.size());
  if (!out) throw std::runtime_error("failed writing " + path);
}

using Clock = std::chrono::steady_clock;
inline double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// main() of a harness: parse, run, write; a one-line message and exit 1 on bad input.
template <class RunFn>
int harness_main(int argc, char** argv, RunFn run_fn) {
  try {
    Run run;
    if (!parse_run(argc, argv, run)) return 0;
    write_output(run_fn(run), run.output);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}

}  // namespace harness
