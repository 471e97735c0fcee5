#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
#
# The main job: set-up, then kiseki's demo on the map kept in data/ (results in results/demo/).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/setup.sh"
cd "$KISEKI_ROOT"
kiseki demo --out results/demo "$@"
