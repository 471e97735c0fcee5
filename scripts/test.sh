#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# The whole test suite: set-up, ruff, C++ GoogleTest suites with ctest (warnings as errors),
# the same suites under AddressSanitizer + UndefinedBehaviorSanitizer, the libFuzzer targets of
# the C++ readers, then pytest (with the atheris targets of the Python readers).
# Fails when any step fails. Extra arguments go to pytest.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "$KISEKI_ROOT"
export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}"

echo "== ruff"
ruff check py tests benchmarks examples scripts
ruff format --check py tests benchmarks examples scripts

echo "== C++ tests (Release, -Werror)"
cmake -S . -B build/cpp -G Ninja -DCMAKE_BUILD_TYPE=Release -DKISEKI_WARNINGS_AS_ERRORS=ON >/dev/null
cmake --build build/cpp
ctest --test-dir build/cpp --output-on-failure --timeout 300

echo "== C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DKISEKI_SANITIZE=ON >/dev/null
cmake --build build/asan
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/asan --output-on-failure --timeout 600

echo "== C++ readers under libFuzzer + ASan + UBSan (fixed runs and seed)"
cmake -S tests/fuzz/cpp -B build/fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build/fuzz
tests/fuzz/cpp/run.sh build/fuzz "${KISEKI_FUZZ_CPP_RUNS:-20000}"

echo "== pytest"
python -m pytest --durations=15 "$@"  # the slowest tests, in every run
