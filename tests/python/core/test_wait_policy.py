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
    ("given", "seen"), [(None, "'PASSIVE'"), ("ACTIVE", "'ACTIVE'"), ("passive", "'passive'")]
)
def test_the_wait_policy_is_passive_unless_the_user_set_one(given, seen):
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    done = subprocess.run([sys.executable, "-c", SHOW], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == seen
