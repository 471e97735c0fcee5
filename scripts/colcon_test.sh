#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# The C++ library as a plain CMake package in a colcon workspace: build it in Release with
# warnings as errors, install it, run every GoogleTest suite through colcon's ctest, and check
# that the library and its headers were installed and that the suites ran and passed.
# This is the test suite's one Release build of the C++ tests (ctest's own stage would build
# the same thing a second time). Usage: colcon_test.sh WORKSPACE (created if missing; reused).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
ws="${1:?usage: colcon_test.sh WORKSPACE}"
mkdir -p "$ws/src"
ws="$(cd "$ws" && pwd)"
ln -sfn "$root" "$ws/src/kiseki"
export COLCON_HOME="$ws/.colcon"
export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}"
cd "$ws"

fail() { echo "colcon_test: $*" >&2; exit 1; }

colcon build --base-paths src \
  --cmake-args -DCMAKE_BUILD_TYPE=Release -DKISEKI_WARNINGS_AS_ERRORS=ON -GNinja >/dev/null 2>&1 ||
  { cat "$ws"/log/latest_build/kiseki/stdout_stderr.log >&2; fail "colcon build failed"; }
[ -f install/kiseki/lib/libkiseki_core.a ] || fail "install/kiseki/lib/libkiseki_core.a missing"
[ -f install/kiseki/include/kiseki/grid/ray_casting.hpp ] ||
  fail "install/kiseki/include/kiseki/grid/ray_casting.hpp missing"

# ctest runs the suites two at a time (each test is its own process)
colcon test --base-paths src --ctest-args -j "$CMAKE_BUILD_PARALLEL_LEVEL" --timeout 300 >/dev/null ||
  fail "colcon test failed"
summary="$(colcon test-result --test-result-base build --all --verbose)" ||
  { echo "$summary" >&2; fail "C++ tests failed"; }
echo "$summary" | tail -n 1
registered="$(ctest --test-dir build/kiseki -N | sed -n 's/^Total Tests: //p')"
ran="$(echo "$summary" | sed -n 's/^Summary: \([0-9]*\) tests\{0,1\},.*/\1/p')"
[ -n "$ran" ] && [ "$ran" -ge 10 ] && [ "$ran" -ge "$registered" ] ||
  fail "colcon ran ${ran:-no} test cases for $registered registered tests"
