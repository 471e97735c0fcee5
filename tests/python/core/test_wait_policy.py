# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki sets OpenMP's wait policy to passive before its core loads (idle workers sleep rather
than spin: benchmarks/bench_threads_under_load.py), and keeps a policy the user set, in the
process libgomp reads it in."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

SHOW = "import kiseki, os; print(repr(os.environ.get('OMP_WAIT_POLICY')))"


@pytest.mark.parametrize(
    ("given", "seen"),
    [
        (None, "'PASSIVE'"),
        ("ACTIVE", "'ACTIVE'"),
        ("passive", "'passive'"),
        ("GOMP_SPINCOUNT=30000", "None"),  # a spin count: a passive policy would override it
    ],
)
def test_the_wait_policy_is_passive_unless_the_user_set_one(given, seen):
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")}
    if given is not None and given.startswith("GOMP_SPINCOUNT="):
        env["GOMP_SPINCOUNT"] = given.split("=", 1)[1]
    elif given is not None:
        env["OMP_WAIT_POLICY"] = given
    done = subprocess.run([sys.executable, "-c", SHOW], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == seen
