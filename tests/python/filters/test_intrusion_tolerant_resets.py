# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``LocalizeConfig.intrusion_tolerant_resets``: kiseki's ray model with recovery resetting,
the cloud judged lost by penetration only. The 6 m x 4 m room with a pillar, the robot on an
elliptic loop around it (noise-free scans; odometry noise 0.1 with people, 0 in the kidnapping
cases, as test_localize_recovery), one seed.

- With people the map does not hold standing beside the loop (discs of 0.25 m, hiding about
  60 % of the beams), the plain agreement calls the true cloud lost and its resets carry it
  metres away (the control: the switch must matter here); with the switch no reset is made,
  and the run is the same as the one without recovery, which tracks.
- A robot kidnapped as in test_localize_recovery (its odometry frame jumps) is still found
  again with the switch: the beams of a wrong place pass through its walls.
- ``kiseki localize --intrusion-tolerant-resets``: refused where it would do nothing, saved
  with the run where it is in effect.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import yaml

from _helpers.room_log import ANGLES, room, write_inputs
from kiseki.datasets import UnknownObstacles, occlude_scans
from kiseki.filters import LocalizeConfig, localize
from kiseki.scans import LaserScans

STEPS, KIDNAP, PEOPLE = 240, 80, 30
# the odometry frame's offset after the kidnapping: x, y (m), theta (rad)
JUMPS = [(0.0, 0.0, np.pi), (2.5, 1.0, 1.5), (1.5, -0.5, 2.5)]


def _loop() -> np.ndarray:
    """The true poses: an ellipse (radii 2.0 and 1.2 m) around the pillar, facing along it."""
    a = np.linspace(0.0, 2.0 * np.pi, STEPS, endpoint=False)
    x, y = 2.15 + 2.0 * np.cos(a), -0.25 + 1.2 * np.sin(a)
    return np.column_stack([x, y, np.arctan2(1.2 * np.cos(a), -2.0 * np.sin(a))])


def _scans(odometry: np.ndarray) -> LaserScans:
    truth = _loop()
    ranges = room().cast_scans(truth, ANGLES, max_range=8.0).astype(np.float32)
    return LaserScans(0.1 * np.arange(STEPS), truth, odometry, ranges, ANGLES, 8.0)


def _people(layout: int) -> UnknownObstacles:
    """Discs of 0.25 m 0.5-0.9 m to either side of poses of the loop (seeded by ``layout``)."""
    truth, rng = _loop(), np.random.default_rng(layout)
    at = truth[rng.integers(0, STEPS, PEOPLE)]
    side = rng.choice([-1.0, 1.0], PEOPLE) * rng.uniform(0.5, 0.9, PEOPLE)
    centres = at[:, :2] + side[:, None] * np.column_stack([-np.sin(at[:, 2]), np.cos(at[:, 2])])
    none = np.zeros((0, 2))
    return UnknownObstacles(centres, np.full(PEOPLE, 0.25), none, none, np.zeros(0))


def _run(scans, recovery: str, tolerant: bool, noise=0.1, proposal="matcher", particles=1000):
    config = LocalizeConfig(
        method="ray-space-observation",
        seed=4,
        particles=particles,
        odometry_noise=noise,
        recovery=recovery,
        intrusion_tolerant_resets=tolerant,
        sensor_reset_proposal=proposal,
    )
    result = localize(scans, room(), config)
    errors = np.hypot(*(result.estimates[:, :2] - scans.poses[:, :2]).T)
    return result, errors


@pytest.mark.parametrize("layout", [0, 1, 2])
def test_people_hiding_the_view_do_not_make_the_tolerant_resets_fire(layout):
    seen, cut = occlude_scans(_scans(_loop()), _people(layout))
    assert cut > 0.5  # most of the view is hidden
    # uniform candidates and 300 particles: the plain arm's resets weigh their candidates with
    # the ray model on every lost update, most of this test's time (30 s with the matcher)
    plain, plain_errors = _run(seen, "resetting", False, proposal="uniform", particles=300)
    tolerant, tolerant_errors = _run(seen, "resetting", True, proposal="uniform", particles=300)
    without, without_errors = _run(seen, "none", tolerant=False, particles=300)
    # the control: the plain agreement calls the true cloud lost and a reset carries it away
    assert np.sum(plain.resets != "none") > 0
    assert plain_errors.max() > 1.0
    # the switch: no reset, the run without recovery's trajectory, which tracks
    assert np.all(tolerant.resets == "none")
    np.testing.assert_array_equal(tolerant.estimates, without.estimates)
    assert tolerant_errors.max() < 0.2
    assert without_errors.max() < 0.2


@pytest.mark.parametrize("jump", JUMPS, ids=["half-turn", "far", "turned-back"])
def test_a_kidnapped_robot_is_still_found_with_the_tolerant_resets(jump):
    truth = _loop()
    dx, dy, dth = jump
    c, s = np.cos(dth), np.sin(dth)
    odometry = truth.copy()
    x, y, theta = truth[KIDNAP:].T
    odometry[KIDNAP:] = np.column_stack([dx + c * x - s * y, dy + s * x + c * y, theta + dth])
    result, errors = _run(_scans(odometry), "resetting", tolerant=True, noise=0.0)
    assert errors[:KIDNAP].max() < 0.1  # tracking before the kidnapping
    assert errors[KIDNAP] > 1.0  # the jump threw the filter off
    assert np.sum(result.resets[KIDNAP:] != "none") > 0
    assert np.median(errors[-60:]) < 0.1  # found again


def _localize(folder, *args):
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "localize", "log.mcap", "--map", "room.yaml",
         "-o", "out.csv", *args],
        cwd=folder, capture_output=True, text=True, timeout=300,
    )  # fmt: skip


def test_the_command_refuses_the_switch_where_it_does_nothing_and_saves_it(tmp_path):
    with pytest.raises(ValueError, match="applies only to ray-space-observation"):
        LocalizeConfig(method="beam", recovery="resetting", intrusion_tolerant_resets=True)
    with pytest.raises(ValueError, match="only with recovery resetting"):
        LocalizeConfig(method="ray-space-observation", intrusion_tolerant_resets=True)
    write_inputs(tmp_path)
    for args, word in (
        (["--recovery", "resetting"], "to --method likelihood-field"),
        (["--method", "ray-space-observation"], "with --recovery none"),
    ):
        done = _localize(tmp_path, *args, "--intrusion-tolerant-resets")
        assert done.returncode != 0
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and word in lines[0] and "--intrusion-tolerant-resets" in lines[0]
        assert not (tmp_path / "out.csv").exists()
    ray = ["--method", "ray-space-observation", "--recovery", "resetting"]
    done = _localize(tmp_path, *ray, "--intrusion-tolerant-resets")
    assert done.returncode == 0, done.stderr
    assert yaml.safe_load((tmp_path / "out.config.yaml").read_text())["intrusion_tolerant_resets"]
