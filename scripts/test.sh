#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# The whole test suite: set-up, ruff, the C++ GoogleTest suites built and run by colcon (Release,
# warnings as errors), the same suites under AddressSanitizer + UndefinedBehaviorSanitizer, the
# libFuzzer targets of the C++ readers, then pytest on two workers (with the atheris targets of
# the Python readers). Every stage prints how long it took.
# Fails when any step fails. Extra arguments go to pytest.
set -euo pipefail
SECONDS=0
stage_name="set-up"
stage_start=0
# Closes the previous stage with its wall time and opens the next one.
stage() {
  printf '   (%s: %d s; %d s in all)\n' "$stage_name" $((SECONDS - stage_start)) "$SECONDS"
  [ $# -eq 0 ] && return 0
  stage_name="$1"
  stage_start=$SECONDS
  echo "== $1"
}
trap stage EXIT
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "$KISEKI_ROOT"
export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}"

stage "ruff"
ruff check py tests benchmarks examples scripts
ruff format --check py tests benchmarks examples scripts

stage "C++ tests (Release, -Werror), built, installed and run by colcon"
bash scripts/colcon_test.sh build/colcon

ccache --show-stats | grep -i "hits" || true

stage "C++ tests under AddressSanitizer + UndefinedBehaviorSanitizer"
# -O1, as the AddressSanitizer manual advises: Eigen at -O0 made one Monte Carlo test take 100 s;
# -g1 (line tables): a report still names file and line, and the build takes about half the time
cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
  -DKISEKI_SANITIZE=ON >/dev/null
cmake --build build/asan
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build/asan --output-on-failure --timeout 600 -j "$CMAKE_BUILD_PARALLEL_LEVEL"

stage "C++ readers under libFuzzer + ASan + UBSan (fixed runs and seed)"
cmake -S tests/fuzz/cpp -B build/fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build/fuzz
tests/fuzz/cpp/run.sh build/fuzz "${KISEKI_FUZZ_CPP_RUNS:-20000}"

stage "pytest"
# two workers on two cores: each worker's BLAS (numpy's OpenBLAS) on one thread. With two
# threads per worker, each waits for a core the other worker holds (a hyperparameter fit of
# 1 s took 113 s in a full run, and 3.4 s instead of 1.4 s beside one other BLAS process).
# kiseki's own threads are the tests' to set; a value given by the caller is kept.
export OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-1}"
# two workers, each taking the next test when free; the slowest tests listed in every run
python -m pytest -n "${KISEKI_TEST_WORKERS:-2}" --dist worksteal --durations=15 "$@"
