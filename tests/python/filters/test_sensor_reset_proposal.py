# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The sensor reset's matcher proposal: in a synthetic room without symmetry, a cloud tracking
the wrong place is reset around the correlative matcher's hypotheses for the scan (every
candidate drawn within a few lattice steps of one), where the uniform proposal's candidates,
the reference, spread over the room; both end at the truth; a lost filter searches on every
k-th reset and moves the places between with the odometry; the same particles for one and two
threads; bad settings refused in one line."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
import yaml

from _helpers.asymmetric_room import RES, room
from _helpers.room_log import write_inputs
from kiseki import _core
from kiseki.filters import MclConfig, MonteCarloLocalizer, RelocalizeConfig, Relocalizer
from kiseki.filters.tracking import LocalizeConfig

ANGLES = np.linspace(-math.pi / 2, math.pi / 2, 181)
TRUTH = np.array([3.0, 5.5, 0.3])
WRONG = np.array([9.0, 2.5, 2.0])  # where the cloud tracks before the first update


def _config(proposal: str, threads: int = 1, **more) -> MclConfig:
    # a sensor reset at the first lost update, made at once (the proposal is what is tested,
    # not its confirmation), every particle from the candidates
    return MclConfig(
        particles=500,
        recovery="resetting",
        reset_after=1,
        sensor_reset_after=1,
        sensor_reset_share=1.0,
        sensor_reset_proposal=proposal,
        threads=threads,
        **({"sensor_reset_candidates": 2000, "sensor_reset_confirm": False} | more),
    )


def _run(proposal: str, threads: int = 1, updates: int = 6, **more):
    """The robot stands at TRUTH; the cloud starts around WRONG. Returns the particles after
    the first update (the reset's), the reports and the final estimate."""
    grid = room()
    ranges = grid.cast_scans(TRUTH[None, :], ANGLES, max_range=20.0)[0]
    model = _core.LikelihoodFieldModel(grid, sigma_hit=0.2, z_hit=0.95, z_rand=0.05, max_beams=90)
    model.set_scan(ANGLES, np.asarray(ranges, np.float32), 20.0)
    localizer = MonteCarloLocalizer(_config(proposal, threads, **more), seed=3, free_space=grid)
    if proposal == "matcher":
        localizer.set_matcher(Relocalizer(grid, 20.0, RelocalizeConfig(threads=threads)))
    localizer.initialize(WRONG, (0.1, 0.1, 0.05))
    reports, first = [], None
    for _ in range(updates):
        reports.append(localizer.step(TRUTH, lambda: model, (ANGLES, ranges)).reset)
        if first is None:
            first = localizer.poses.copy()
    return first, reports, localizer.estimate, (grid, ranges)


def _near_hypotheses(poses: np.ndarray, grid, ranges) -> np.ndarray:
    """Whether each pose lies within 5 SDs of the proposal's spread (one cell per axis, one
    heading step) of one of the matcher's hypotheses for the scan."""
    relocalizer = Relocalizer(grid, 20.0)
    found = relocalizer.match(ANGLES, ranges)
    step = 2 * math.pi / relocalizer.headings(ANGLES, ranges)
    near = np.zeros(len(poses), dtype=bool)
    for h in found:
        d = np.hypot(poses[:, 0] - h.x, poses[:, 1] - h.y)
        a = np.abs(np.remainder(poses[:, 2] - h.theta + math.pi, 2 * math.pi) - math.pi)
        near |= (d < 5 * math.sqrt(2) * RES) & (a < 5 * step)
    return near


def test_the_matcher_proposal_resets_around_the_hypotheses_and_ends_at_the_truth():
    first, reports, estimate, (grid, ranges) = _run("matcher")
    assert reports[0] == "sensor"
    assert _near_hypotheses(first, grid, ranges).all()
    assert math.hypot(*(estimate[:2] - TRUTH[:2])) < 0.3
    # the reference: the uniform proposal's candidates spread over the room, and it too ends
    # at the truth (one scan of this room fits one place); its successive resets are each
    # accepted on the likelihood alone
    first_u, reports_u, estimate_u, _ = _run("uniform", reset_needs_agreement=False)
    assert reports_u[0] == "sensor"
    assert _near_hypotheses(first_u, grid, ranges).mean() < 0.5
    assert math.hypot(*(estimate_u[:2] - TRUTH[:2])) < 0.3
    # with the agreement check (the default), no place that 2,000 uniform candidates propose
    # lies close enough to the truth for the map to agree with the scan from it: refused; of
    # the engine's 20,000, one does, and the first reset lands near the truth
    _, reports_few, _, _ = _run("uniform")
    assert "sensor" not in reports_few
    _, reports_many, estimate_many, _ = _run("uniform", sensor_reset_candidates=20_000)
    assert reports_many[0] == "sensor"
    assert math.hypot(*(estimate_many[:2] - TRUTH[:2])) < 0.5


def _lost_walk(every: int, updates: int = 7):
    """The robot drives 0.15 m per update from TRUTH along its heading (the odometry exact);
    the cloud starts at WRONG and every reset is refused (an evidence no place can give), so
    the lost spell lasts. Returns the reports' search flags, the matcher's places after each
    update, and the true poses."""
    grid = room()
    relocalizer = Relocalizer(grid, 20.0, RelocalizeConfig(threads=1))
    localizer = MonteCarloLocalizer(
        _config("matcher", matcher_search_every=every, reset_evidence=1e6),
        seed=3,
        free_space=grid,
    )
    localizer.set_matcher(relocalizer)
    localizer.initialize(WRONG, (0.1, 0.1, 0.05))
    model = _core.LikelihoodFieldModel(grid, sigma_hit=0.2, z_hit=0.95, z_rand=0.05, max_beams=90)
    searched, places, truths = [], [], []
    for k in range(updates):
        pose = TRUTH + 0.15 * k * np.array([math.cos(TRUTH[2]), math.sin(TRUTH[2]), 0.0])
        ranges = grid.cast_scans(pose[None, :], ANGLES, max_range=20.0)[0]
        model.set_scan(ANGLES, np.asarray(ranges, np.float32), 20.0)
        report = localizer.step(pose, lambda: model, (ANGLES, ranges))
        assert report.reset == "none"  # every reset refused: one lost spell
        searched.append(report.searched)
        places.append(localizer.matcher_hypotheses.copy())
        truths.append(pose)
    return searched, places, truths


def test_a_lost_filter_searches_on_every_kth_reset_and_moves_the_places_with_the_odometry():
    # the closed form: a search on the spell's resets 1, k + 1, 2k + 1, ...
    for every in (1, 3, 1000):
        searched, places, truths = _lost_walk(every)
        assert searched == [k % every == 0 for k in range(7)], every
    # between searches the places move with the odometry: after 0.9 m the best of the first
    # search's places is where a search of the new scan puts it (the reference), within the
    # proposal's spread of a cell and a heading step; the control, the first search's place
    # unmoved, is 0.9 m off (places and truths: the last walk's, a search on the first reset only)
    reference = Relocalizer(room(), 20.0)
    ranges = room().cast_scans(truths[-1][None, :], ANGLES, max_range=20.0)[0]
    best = reference.match(ANGLES, ranges)[0]
    step = 2 * math.pi / reference.headings(ANGLES, ranges)
    moved = places[-1][0]
    assert math.hypot(moved[0] - best.x, moved[1] - best.y) < 2 * RES
    assert abs(math.remainder(moved[2] - best.theta, 2 * math.pi)) < 1.5 * step
    assert math.hypot(*(places[0][0][:2] - truths[-1][:2])) > 0.85


def test_the_matcher_proposal_gives_the_same_particles_for_one_and_two_threads():
    one, reports_one, _, _ = _run("matcher", threads=1, updates=3)
    two, reports_two, _, _ = _run("matcher", threads=2, updates=3)
    assert reports_one == reports_two
    np.testing.assert_array_equal(one, two)


def test_bad_settings_are_refused_in_one_line(tmp_path):
    for bad, word in (
        (dict(sensor_reset_proposal="grid"), "sensor_reset_proposal must be one of"),
        (dict(reset_look_elsewhere=1), "reset_look_elsewhere must be True or False"),
        (dict(reset_needs_agreement="yes"), "reset_needs_agreement must be True or False"),
        (dict(sensor_reset_confirm=0), "sensor_reset_confirm must be True or False"),
        (dict(matcher_search_every=0), "matcher_search_every must be an integer in 1..1,000"),
    ):
        with pytest.raises(ValueError, match=word) as caught:
            LocalizeConfig(**bad)
        assert "\n" not in str(caught.value)
    # the matcher proposal without a matcher, or without the scan, is refused at the update
    grid = room()
    ranges = grid.cast_scans(TRUTH[None, :], ANGLES, max_range=20.0)[0]
    model = _core.LikelihoodFieldModel(grid, max_beams=90)
    model.set_scan(ANGLES, np.asarray(ranges, np.float32), 20.0)
    localizer = MonteCarloLocalizer(_config("matcher"), seed=3, free_space=grid)
    localizer.initialize(WRONG, (0.1, 0.1, 0.05))
    with pytest.raises(RuntimeError, match="needs a correlative scan matcher"):
        localizer.step(TRUTH, lambda: model, (ANGLES, ranges))
    with pytest.raises(RuntimeError, match="needs the scan"):
        localizer.step(TRUTH, lambda: model)
    write_inputs(tmp_path)  # the helpers' room and a run log through it
    for args, word in (
        (["--recovery", "resetting", "--reset-proposal", "grid"], "sensor_reset_proposal must be"),
        (["--global", "--reset-proposal", "matcher"], "does not apply with --global"),
        (["--global", "--reset-unchecked"], "does not apply with --global"),
        (
            [
                "--recovery",
                "resetting",
                "--reset-proposal",
                "uniform",
                "--matcher-search-every",
                "3",
            ],
            "does not apply without --reset-proposal matcher",
        ),
        # the reset options without sensor resets (they were ignored, and saved as if in effect)
        (["--reset-unchecked"], "does not apply with --recovery none"),
        (["--recovery", "augmented", "--reset-proposal", "uniform"], "with --recovery augmented"),
        (["--method", "odometry", "--reliability", "learned"], "to --method odometry"),
        (
            ["--reset-proposal", "matcher", "--matcher-search-every", "0"],
            "--matcher-search-every must be",
        ),
    ):
        done = subprocess.run(
            [sys.executable, "-m", "kiseki.cli", "localize", "log.mcap", "--map", "room.yaml",
             "-o", "out.csv", *args],
            cwd=tmp_path, capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert done.returncode != 0
        assert word in done.stderr and "Traceback" not in done.stderr


def test_reset_unchecked_runs_the_resets_without_both_checks_and_saves_it(tmp_path):
    write_inputs(tmp_path)
    for name, args, checked in (("a", [], True), ("b", ["--reset-unchecked"], False)):
        done = subprocess.run(
            [sys.executable, "-m", "kiseki.cli", "localize", "log.mcap", "--map", "room.yaml",
             "-o", f"{name}.csv", "--recovery", "resetting", *args],
            cwd=tmp_path, capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        saved = yaml.safe_load((tmp_path / f"{name}.config.yaml").read_text())
        assert saved["reset_needs_agreement"] is checked
        assert saved["sensor_reset_confirm"] is checked
