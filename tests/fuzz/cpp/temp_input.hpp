// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// The readers under test take a file name: each fuzz input is written to a file of its own,
// created by mkstemp in $TMPDIR (/tmp when unset) and removed when the TempInput goes out of
// scope. The targets keep it only around the read, so that a finding reported by their own
// checks (std::abort, which skips destructors) leaves no file behind either; libFuzzer keeps the
// input itself as crash-*.
#pragma once

#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace kiseki_fuzz {

class TempInput {
 public:
  TempInput(const std::uint8_t* data, std::size_t size) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir != nullptr && *dir != '\0' ? dir : "/tmp") + "/kiseki-fuzz-XXXXXX";
    const int fd = mkstemp(path_.data());
    if (fd < 0) std::abort();  // the harness cannot run: not a finding, but nothing to test
    while (size > 0) {
      const ssize_t n = write(fd, data, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        close(fd);
        unlink(path_.c_str());
        std::abort();
      }
      data += n;
      size -= static_cast<std::size_t>(n);
    }
    if (close(fd) != 0) {
      unlink(path_.c_str());
      std::abort();
    }
  }
  ~TempInput() { unlink(path_.c_str()); }
  TempInput(const TempInput&) = delete;
  TempInput& operator=(const TempInput&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace kiseki_fuzz
