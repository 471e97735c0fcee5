#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# Runs the libFuzzer targets built from this folder for a fixed number of executions each
# (deterministic: -seed=1), seeded from seeds/, the project's data/maps and, when present, the
# recorded maps of ../shared/data. Usage: run.sh BUILD_DIR [RUNS]. A crash leaves its input in
# BUILD_DIR/crash-* and fails the script; each target's log is BUILD_DIR/fuzz_<target>.log.
set -euo pipefail
build="$(cd "$1" && pwd)"
runs="${2:-20000}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../../.." && pwd)"
shared="$root/../shared/data"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

mkdir -p "$work/map_image" "$work/octree" "$work/pcd"
cp "$here"/seeds/map_image/* "$work/map_image/"
cp "$here"/seeds/octree/* "$work/octree/"
cp "$here"/seeds/pcd/* "$work/pcd/"
[ -f "$shared/pcd/sac_plane_test.pcd" ] && cp "$shared/pcd/sac_plane_test.pcd" "$work/pcd/"
# map_image inputs start with one byte choosing the YAML fields (0: trinary, nav2's defaults)
for image in "$root"/data/maps/*.pgm "$shared"/carmen/*.png; do
  [ -f "$image" ] && { printf '\000'; cat "$image"; } > "$work/map_image/$(basename "$image")"
done
# the recorded building (209 kB, 0.5 M nodes) is read up to -max_len: its header and first
# nodes (a whole tree per execution would take 0.2 s)
[ -f "$shared/octomap/geb079.bt" ] && cp "$shared/octomap/geb079.bt" "$work/octree/"
max_len_map_image=131072
max_len_octree=16384
max_len_pcd=65536

for target in map_image octree pcd; do
  echo "== fuzz_$target: $runs runs"
  max_len="max_len_$target"
  "$build/fuzz_$target" -runs="$runs" -seed=1 -max_len="${!max_len}" -timeout=30 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/" "$work/$target" \
    > "$build/fuzz_$target.log" 2>&1 || { tail -n 60 "$build/fuzz_$target.log"; exit 1; }
  grep -a '^Done\|stat::number_of_executed_units\|stat::peak_rss' "$build/fuzz_$target.log"
done
