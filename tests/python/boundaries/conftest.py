# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The failure-injection tests' shared runs: a short teaching run and an experiment sweep, each
made once, uninterrupted, as the reference a cut-short run is compared with."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from _helpers.injection import KISEKI, ROOT, SWEEP, TIMEOUT, namespace_refusal


@pytest.fixture(scope="session")
def namespace() -> None:
    reason = namespace_refusal()
    if reason is not None:
        pytest.skip(f"a small tmpfs needs a user + mount namespace: {reason}")


@pytest.fixture(scope="session")
def scene(tmp_path_factory) -> Path:
    """The factory corridor with a route of 5 m instead of 13 m (about 110 steps)."""
    text = (ROOT / "data" / "worlds" / "factory_corridor.yaml").read_text()
    route = "waypoints: [[0.0, 0.0], [7.4, 0.0], [13.0, 0.0]]"
    assert route in text
    path = tmp_path_factory.mktemp("scene") / "short_corridor.yaml"
    path.write_text(text.replace(route, "waypoints: [[0.0, 0.0], [2.5, 0.0], [5.0, 0.0]]"))
    return path


@pytest.fixture(scope="session")
def taught(tmp_path_factory, scene) -> dict:
    """An uninterrupted teaching run with seed 0 (the CLI runs compared with it pass --seed 0):
    its folder, marks, poses."""
    from kiseki.apps.teach import teach
    from kiseki.io.runlog import read_run
    from kiseki.sim.scene import load_scene

    result = teach(load_scene(scene), tmp_path_factory.mktemp("taught") / "t", seed=0)
    assert [m["name"] for m in result.marks] == ["P0", "P1", "P2"]
    poses = read_run(result.log).poses("/ground_truth")[1]
    return {
        "folder": result.log.parent,
        "marks": result.marks,
        "poses": poses,
        "steps": result.steps,
    }


@pytest.fixture(scope="session")
def swept(tmp_path_factory) -> Path:
    """An uninterrupted experiment sweep (about 0.4 s a trial)."""
    out = tmp_path_factory.mktemp("swept") / "e"
    done = subprocess.run(
        [*KISEKI.split(), "experiment", "run", *SWEEP, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )
    assert done.returncode == 0, done.stderr
    return out
