#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# Idempotent set-up, sourced by scripts/demo.sh and scripts/test.sh:
#   1. Debian packages (apt-get, through sudo when not root), only when one is missing;
#   2. .venv/ at the project root with the build tools and Python dependencies;
#   3. kiseki installed editable into .venv, again only when C++/CMake sources changed or a
#      Python module was added, moved or removed.
# A second run does no download and no compilation when nothing changed. C++ builds go through
# ccache, in ccache's own cache (~/.cache/ccache unless CCACHE_DIR or ccache's settings say
# otherwise), so that a fresh clone in the same folder compiles only what changed.
set -euo pipefail

KISEKI_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
KISEKI_VENV="$KISEKI_ROOT/.venv"
KISEKI_PYTHON="${KISEKI_PYTHON:-python3}"

APT_PACKAGES=(
  build-essential pkg-config git
  python3 python3-venv python3-dev
  libeigen3-dev libpcl-dev liboctomap-dev libopencv-dev octomap-tools
  libopenblas-dev liblapacke-dev  # the Gaussian processes' Cholesky factorisations (kiseki/gp)
  libgtest-dev googletest
  chromium  # the serve page's browser tests (Playwright drives it; it downloads no browser)
  clang libclang-rt-dev  # libFuzzer targets of the C++ readers (tests/fuzz/cpp)
  ccache  # the compiler cache every build here goes through (below)
  librange-v3-dev libtbb-dev  # beluga's dependencies: the side-by-side harnesses (benchmarks/anchors)
)

log() { printf '[setup] %s\n' "$*" >&2; }

install_debian_packages() {
  local missing=()
  for pkg in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" ||
      missing+=("$pkg")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  log "installing Debian packages: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
}

# A hash of the files that decide what must be (re)installed.
tree_hash() {
  (cd "$KISEKI_ROOT" && find "$@" -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.txt' \
    -o -name '*.cmake' -o -name '*.toml' \) -print0 2>/dev/null | sort -z |
    xargs -0 sha1sum | sha1sum | cut -d' ' -f1)
}

setup_venv() {
  if [ ! -x "$KISEKI_VENV/bin/python" ]; then
    log "creating $KISEKI_VENV"
    "$KISEKI_PYTHON" -m venv "$KISEKI_VENV"
  fi
  local deps_stamp="$KISEKI_VENV/.kiseki-deps" deps_hash
  deps_hash="$(sha1sum "$KISEKI_ROOT/pyproject.toml" | cut -d' ' -f1)"
  if [ "$(cat "$deps_stamp" 2>/dev/null)" != "$deps_hash" ]; then
    log "installing Python build tools and dependencies into .venv"
    "$KISEKI_VENV/bin/python" -m pip install -q --upgrade pip
    "$KISEKI_VENV/bin/python" -m pip install -q "scikit-build-core>=0.10" "pybind11>=2.12" \
      "cmake>=3.22" ninja
    "$KISEKI_VENV/bin/python" - "$KISEKI_ROOT/pyproject.toml" > "$KISEKI_VENV/.kiseki-reqs" <<'PY'
import sys, tomllib
project = tomllib.load(open(sys.argv[1], "rb"))["project"]
print("\n".join(project["dependencies"] + project["optional-dependencies"]["test"]))
PY
    "$KISEKI_VENV/bin/python" -m pip install -q -r "$KISEKI_VENV/.kiseki-reqs"
    echo "$deps_hash" > "$deps_stamp"
    rm -f "$KISEKI_VENV/.kiseki-build"
  fi
  local build_stamp="$KISEKI_VENV/.kiseki-build" build_hash
  # the editable install maps each Python module by name, so a module added, moved or removed
  # needs it again as much as a changed C++ source does
  build_hash="$(tree_hash cpp bindings cmake CMakeLists.txt pyproject.toml)-$(
    cd "$KISEKI_ROOT" && find py -name '*.py' -not -path '*/__pycache__/*' | sort | sha1sum |
      cut -d' ' -f1)"
  if [ "$(cat "$build_stamp" 2>/dev/null)" != "$build_hash" ]; then
    log "building and installing kiseki (incremental C++ build in build/editable)"
    (cd "$KISEKI_ROOT" && CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-2}" \
      "$KISEKI_VENV/bin/python" -m pip install -q --no-build-isolation --no-deps -e . \
      -Cbuild-dir=build/editable)
    echo "$build_hash" > "$build_stamp"
  fi
}

install_debian_packages
# Every C++ build goes through the user's compiler cache (ccache's default folder, as pip's wheels
# sit in pip's), with paths inside the repository hashed relative to the build folder (base_dir;
# every build folder is two levels down: build/editable, build/kiseki of the colcon test,
# build/asan, build/anchors) and without the build folder itself (hash_dir off): the colcon build
# takes the library's objects from the editable install's compiles, and a rebuild or a fresh
# clone anywhere compiles only what changed.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$KISEKI_ROOT}"
export CCACHE_NOHASHDIR="${CCACHE_NOHASHDIR:-true}"
export CMAKE_CXX_COMPILER_LAUNCHER="${CMAKE_CXX_COMPILER_LAUNCHER:-ccache}"
export CXX="${CXX:-g++}"
setup_venv
export PATH="$KISEKI_VENV/bin:$PATH"
