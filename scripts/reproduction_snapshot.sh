#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# Commits a full reproduction run's verdicts to the repository: copies from each finished
# experiment's run in RESULTS (the layout of `kiseki experiment run '*' --out RESULTS`, or
# RESULTS/NAME/latest) what the report reads (claims.csv, config.yaml, manifest.json,
# timings.parquet, tables/*.csv; not the trials, figures or report.md) into
# docs/reproduction/results/NAME/run/, then regenerates docs/reproduction/REPRODUCTION.md and
# the README's marked tables from them. A test checks that the README's tables are what these
# files give.
#
#   bash scripts/reproduction_snapshot.sh RESULTS
set -euo pipefail
if [ $# -ne 1 ] || [ ! -d "$1" ]; then
  echo "usage: bash scripts/reproduction_snapshot.sh RESULTS (a folder of experiment runs)" >&2
  exit 2
fi
results="$(cd "$1" && pwd)"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
kiseki="${KISEKI:-$root/.venv/bin/kiseki}"
snapshot="$root/docs/reproduction/results"
mkdir -p "$snapshot"
for folder in "$results"/*/; do
  name="$(basename "$folder")"
  run="$folder"
  [ -f "$folder/latest/claims.csv" ] && run="$folder/latest"
  [ -f "$run/claims.csv" ] || continue  # not finished (or every trial failed)
  target="$snapshot/$name/run"
  rm -rf "$target.new"
  mkdir -p "$target.new/tables"
  cp "$run"/claims.csv "$run"/config.yaml "$run"/manifest.json "$target.new/"
  [ -f "$run/timings.parquet" ] && cp "$run/timings.parquet" "$target.new/"
  cp "$run"/tables/*.csv "$target.new/tables/" 2>/dev/null || true
  # the run's own checkout's absolute paths to the repository's data/ as data/...: the same
  # files in any clone, and no machine's folders in the repository
  sed -i -E 's#: /[^ ]*/(data(/[^ ]*)?)$#: \1#' "$target.new/config.yaml"
  rm -rf "$target"
  mv "$target.new" "$target"
  ln -sfn run "$snapshot/$name/latest"
  echo "$name: $(grep -c . "$target/claims.csv") lines of claims"
done
"$kiseki" experiment report --results "$snapshot" -o "$root/docs/reproduction/REPRODUCTION.md" \
  --readme "$root/README.md"
