#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# The C++ library as a plain CMake package in a colcon workspace: build it in Release with
# warnings as errors, install it, run every GoogleTest suite through colcon's ctest, and check
# that the library and its headers were installed and that the suites ran and passed.
# This is the test suite's one Release build of the C++ tests (ctest's own stage would build
# the same thing a second time). Usage: colcon_test.sh WORKSPACE (created if missing; reused).
# The package's build folder is build/kiseki, two levels below the repository as the editable
# install's build/editable is: with the compiler cache's base folder at the repository
# (scripts/setup.sh) the library's compile commands then read the same, and the cache serves
# them from the editable install's compiles, in this clone or in another one.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ws="${1:?usage: colcon_test.sh WORKSPACE}"
mkdir -p "$ws"
ws="$(cd "$ws" && pwd)"
export COLCON_HOME="$ws/.colcon"
export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}"
# colcon builds with -jN -lN (N cores) unless MAKEFLAGS sets the jobs; the load limit held the
# build to one job at a time after the set-up's compile had raised the load average
export MAKEFLAGS="-j$CMAKE_BUILD_PARALLEL_LEVEL"
cd "$ws"
build_base="$root/build"

fail() { echo "colcon_test: $*" >&2; exit 1; }

# the package by its own path (not a link in src/), so the compiler sees the same paths as the
# editable install's build and the compiler cache (scripts/setup.sh) serves the library from it
colcon build --base-paths "$root" --build-base "$build_base" \
  --cmake-args -DCMAKE_BUILD_TYPE=Release -DKISEKI_WARNINGS_AS_ERRORS=ON -GNinja >/dev/null 2>&1 ||
  { cat "$ws"/log/latest_build/kiseki/stdout_stderr.log >&2; fail "colcon build failed"; }
[ -f install/kiseki/lib/libkiseki_core.a ] || fail "install/kiseki/lib/libkiseki_core.a missing"
[ -f install/kiseki/include/kiseki/grid/ray_casting.hpp ] ||
  fail "install/kiseki/include/kiseki/grid/ray_casting.hpp missing"

# ctest runs the suites two at a time (each test is its own process)
colcon test --base-paths "$root" --build-base "$build_base" \
  --ctest-args -j "$CMAKE_BUILD_PARALLEL_LEVEL" --timeout 300 >/dev/null || fail "colcon test failed"
summary="$(colcon test-result --test-result-base "$build_base/kiseki" --all --verbose)" ||
  { echo "$summary" >&2; fail "C++ tests failed"; }
echo "$summary" | tail -n 1
registered="$(ctest --test-dir "$build_base/kiseki" -N | sed -n 's/^Total Tests: //p')"
ran="$(echo "$summary" | sed -n 's/^Summary: \([0-9]*\) tests\{0,1\},.*/\1/p')"
[ -n "$ran" ] && [ "$ran" -ge 10 ] && [ "$ran" -ge "$registered" ] ||
  fail "colcon ran ${ran:-no} test cases for $registered registered tests"
