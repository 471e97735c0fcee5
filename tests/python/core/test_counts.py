# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every count the library takes (particles, beams, threads, moves, a window's length) goes
through one check, worded as the command line words it: a Python or numpy integer in its range,
never a bool or a float. Before, the counts were checked about thirty ways: np.int64(50)
particles were refused by PlaybackConfig and GlobalConfig as "must be an integer", np.int64 beams
by RelocalizeConfig, a walk's numpy seed by the walks; LocalizeConfig(beams=2**70) was taken and
the C++ model then refused it in a TypeError listing its signatures; the same range read
"0..100000" in one message and "0..100,000" in another."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from kiseki._support.counts import check_count, integer_rule
from kiseki._support.options import BEAM_LIMIT, PARTICLE_LIMIT, THREAD_LIMIT, Count
from kiseki.apps.teach.playback import PlaybackConfig
from kiseki.coop import plan
from kiseki.coop.positioning import paper_angle
from kiseki.coop.simulation import simulate
from kiseki.core import Pose2
from kiseki.errors import RelocalizationError
from kiseki.filters import MclConfig
from kiseki.filters.convergence import elapsed_time
from kiseki.filters.global_localization import GlobalConfig
from kiseki.filters.localize_config import LocalizeConfig
from kiseki.filters.relocalization import RelocalizeConfig
from kiseki.gp.curl_free_basis import laplacian_basis
from kiseki.gp.kernel import fit_hyperparameters, subsample
from kiseki.grid import OccupancyGrid, beam_angles
from kiseki.io.runlog.writer import RunWriter
from kiseki.magnetic.lidar_mcl import LidarMclConfig
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig
from kiseki.magnetic.multi_sensor import DriftCheck
from kiseki.magnetic.rahok_navigation import moving_average
from kiseki.magnetic.travel_distance import TravelDistanceConfig
from kiseki.mapping import endpoint_agreement
from kiseki.metrics import rpe
from kiseki.models.space_observation import visibility_reference
from kiseki.sim.terrain_moves import terrain_stops
from kiseki.speed.baselines import DistanceLimiterConfig
from kiseki.speed.limiter import SpeedLimiterConfig
from kiseki.terrain import correlation_search, sdem_from_points
from kiseki.terrain.baselines import register_pcl


def _grid() -> OccupancyGrid:
    cells = np.zeros((20, 20), np.int8)
    cells[0, :] = 100
    return OccupancyGrid(cells, 0.1, Pose2(0.0, 0.0, 0.0))


def _gp_data():
    x = np.linspace(0.0, 4.0, 12)[:, None]
    return x, np.sin(x[:, 0])


_SDEM = sdem_from_points(np.random.default_rng(0).uniform([-3, -3, -0.6], [3, 3, -0.4], (500, 3)))
_PATH = np.column_stack([np.linspace(0.0, 2.0, 8), np.zeros(8), np.zeros(8)])


def _agreement(n):
    angles = np.linspace(-1.0, 1.0, 5)
    return endpoint_agreement(_grid(), np.array([[1.0, 1.0, 0.0]]), np.ones((1, 5)), angles, 5.0, n)


def _c(call, name: str, low: int, high: int | None, note: str = "", error=ValueError):
    """A count: the call with it, the name its message gives, its range (high None: no upper
    bound), the range's note and the error kind."""
    return call, name, low, high, note, error


CASES = {
    "MclConfig.particles": _c(lambda v: MclConfig(particles=v), "particles", 1, PARTICLE_LIMIT),
    "MclConfig.min_particles": _c(
        lambda v: MclConfig(min_particles=v),
        "min_particles",
        1,
        PARTICLE_LIMIT,
    ),
    "MclConfig.threads": _c(
        lambda v: MclConfig(threads=v),
        "threads",
        0,
        THREAD_LIMIT,
        "0 = chosen by measured time",
    ),
    "MclConfig.matcher_search_every": _c(
        lambda v: MclConfig(matcher_search_every=v),
        "matcher_search_every",
        1,
        1000,
    ),
    "GlobalConfig.particles": _c(
        lambda v: GlobalConfig(particles=v),
        "global localization: particles",
        1,
        PARTICLE_LIMIT,
    ),
    "GlobalConfig.hypotheses": _c(
        lambda v: GlobalConfig(hypotheses=v),
        "global localization: hypotheses",
        1,
        PARTICLE_LIMIT,
    ),
    "GlobalConfig.beams": _c(
        lambda v: GlobalConfig(beams=v),
        "beams",
        0,
        BEAM_LIMIT,
        "0 = every beam",
    ),
    "LocalizeConfig.beams": _c(
        lambda v: LocalizeConfig(beams=v),
        "beams",
        0,
        BEAM_LIMIT,
        "0 = every beam",
    ),
    "LocalizeConfig.budget_min_beams": _c(
        lambda v: LocalizeConfig(budget_min_beams=v),
        "budget_min_beams",
        1,
        BEAM_LIMIT,
    ),
    "RelocalizeConfig.beams": _c(
        lambda v: RelocalizeConfig(beams=v),
        "relocalize: beams",
        0,
        BEAM_LIMIT,
        "",
        RelocalizationError,
    ),
    "RelocalizeConfig.depth": _c(
        lambda v: RelocalizeConfig(depth=v),
        "relocalize: depth",
        0,
        16,
        "",
        RelocalizationError,
    ),
    "PlaybackConfig.particles": _c(
        lambda v: PlaybackConfig(particles=v),
        "particles",
        1,
        PARTICLE_LIMIT,
    ),
    "PlaybackConfig.scan_beams": _c(
        lambda v: PlaybackConfig(scan_beams=v),
        "scan_beams",
        1,
        BEAM_LIMIT,
    ),
    "LoopTravelConfig.particles": _c(
        lambda v: LoopTravelConfig(particles=v),
        "loop filter: particles",
        1,
        PARTICLE_LIMIT,
    ),
    "TravelDistanceConfig.particles": _c(
        lambda v: TravelDistanceConfig(particles=v),
        "travel distance: particles",
        1,
        PARTICLE_LIMIT,
    ),
    "LidarMclConfig.beams": _c(
        lambda v: LidarMclConfig(beams=v),
        "lidar MCL: beams",
        1,
        BEAM_LIMIT,
    ),
    "SpeedLimiterConfig.free_threshold": _c(
        lambda v: SpeedLimiterConfig(free_threshold=v),
        "SpeedLimiterConfig.free_threshold",
        0,
        100,
    ),
    "DistanceLimiterConfig.free_threshold": _c(
        lambda v: DistanceLimiterConfig(free_threshold=v),
        "DistanceLimiterConfig.free_threshold",
        0,
        100,
    ),
    "DriftCheck.window": _c(lambda v: DriftCheck(window=v), "drift check: window", 2, None),
    "plan.moves": _c(lambda v: plan(form=2, moves=v, angle=0.5).sight_angles(), "moves", 1, 1000),
    "paper_angle.moves": _c(lambda v: paper_angle(2, v), "moves", 1, None),
    "simulate.runs": _c(lambda v: simulate(plan(form=2, moves=3), runs=v), "runs", 1, 1_000_000),
    "laplacian_basis.count": _c(lambda v: laplacian_basis([1.0, 1.0], v), "count", 1, 10_000),
    "subsample.max_points": _c(lambda v: subsample(10, v, 0), "max_points", 2, None),
    "beam_angles.count": _c(lambda v: beam_angles(v, math.pi), "beam count", 1, BEAM_LIMIT),
    "endpoint_agreement.neighbourhood": _c(
        _agreement,
        "endpoint_agreement: neighbourhood",
        0,
        10,
        "cells",
    ),
    "visibility_reference.span": _c(
        lambda v: visibility_reference(_grid(), (10, 10), v),
        "visibility_reference: span",
        1,
        1001,
    ),
    "moving_average.cells": _c(
        lambda v: moving_average(np.arange(7.0), v),
        "moving_average: cells",
        1,
        None,
    ),
    "terrain_stops.moves": _c(lambda v: terrain_stops("absent.yaml", v, 0), "moves", 1, 200),
    "register_pcl.max_iterations": _c(
        lambda v: register_pcl(np.zeros((10, 3)), np.zeros((10, 3)), max_iterations=v),
        "max_iterations",
        1,
        100_000,
    ),
    "GlobalConfig.tracking_particles": _c(
        lambda v: GlobalConfig(tracking_particles=v),
        "global localization: tracking_particles",
        1,
        PARTICLE_LIMIT,
    ),
    "LidarMclConfig.particles": _c(
        lambda v: LidarMclConfig(particles=v), "lidar MCL: particles", 1, PARTICLE_LIMIT
    ),
    "fit_hyperparameters.restarts": _c(
        lambda v: fit_hyperparameters(*_gp_data(), restarts=v).start_values, "restarts", 0, 100
    ),
    "correlation_search.min_overlap": _c(
        lambda v: correlation_search(_SDEM, _SDEM, min_overlap=v).overlap,
        "min_overlap",
        1,
        2**31 - 1,
    ),
    "elapsed_time.k": _c(
        lambda v: elapsed_time(np.arange(5.0), v), "elapsed_time: k", 0, 4, "a scan index"
    ),
    "rpe.delta": _c(lambda v: rpe(_PATH, _PATH, delta=v).rmse, "delta", 1, None, "frames"),
}


def _case(label):
    return CASES[label]


def _refused(label, value) -> str:
    call, name, low, high, note, error = _case(label)
    with pytest.raises(error) as caught:
        call(value)
    return str(caught.value)


# the speed configs' check of every field (>= 0 or > 0) refuses a negative count first
LOW_END_CHECKED_BEFORE = {"DistanceLimiterConfig.free_threshold"}


@pytest.mark.parametrize("label", CASES)
def test_each_count_refuses_one_past_either_end_in_the_shared_words(label):
    _, name, low, high, note, _ = _case(label)
    ends = [] if label in LOW_END_CHECKED_BEFORE else [low - 1]
    for past in ends + ([high + 1] if high is not None else []):
        assert (
            _refused(label, past) == f"{name} must be {integer_rule(low, high, note)}, got {past}"
        )


SKIP_VALID = {"simulate.runs", "terrain_stops.moves", "register_pcl.max_iterations"}


@pytest.mark.parametrize("label", sorted(set(CASES) - SKIP_VALID))
def test_each_count_takes_a_numpy_integer_as_its_python_twin(label):
    call, _, low, _, _, _ = _case(label)
    value = max(low, 3)
    a, b = call(np.int64(value)), call(value)
    if isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b)
    elif not isinstance(a, RunWriter):
        assert a == b


# the configs' field kinds are checked first, in check_field_types' words (its own test)
FUNCTIONS = [label for label in CASES if not label[0].isupper()]


@pytest.mark.parametrize("bad", [True, np.bool_(True), 2.0, "3", None])
@pytest.mark.parametrize("label", FUNCTIONS)
def test_a_bool_a_float_or_text_is_no_count(label, bad):
    _, name, low, high, note, _ = _case(label)
    assert _refused(label, bad) == f"{name} must be {integer_rule(low, high, note)}, got {bad!r}"


@pytest.mark.parametrize(
    ("label", "value", "message"),
    [  # the words themselves, not built by the function under test
        (
            "RelocalizeConfig.beams",
            100_001,
            "relocalize: beams must be an integer in 0..100,000, got 100001",
        ),
        (
            "MclConfig.threads",
            -1,
            "threads must be an integer in 0..1,024 (0 = chosen by measured time), got -1",
        ),
        ("DriftCheck.window", 1, "drift check: window must be an integer >= 2, got 1"),
        (
            "elapsed_time.k",
            np.int64(5),
            "elapsed_time: k must be an integer in 0..4 (a scan index), got np.int64(5)",
        ),
    ],
)
def test_the_words_of_a_refused_count(label, value, message):
    assert _refused(label, value) == message


def test_a_count_a_result_keeps_is_python_s_int():
    """plan(2, np.int64(4)).moves stayed np.int64, which a JSON record of the plan refuses."""
    moves = plan(form=2, moves=np.int64(4)).moves
    assert type(moves) is int and json.dumps(moves) == "4"


def test_the_library_and_the_command_line_word_a_range_alike():
    with pytest.raises(ValueError) as library:
        check_count(2**31, "--beams", 0, BEAM_LIMIT, "0 = every beam")
    cli = Count("--beams", 0, BEAM_LIMIT, "0 = every beam")
    with pytest.raises(Exception) as command_line:
        cli("2147483648")
    assert str(library.value) == str(command_line.value)
    assert str(library.value) == (
        "--beams must be an integer in 0..100,000 (0 = every beam), got 2147483648"
    )
    assert (
        check_count(np.uint8(7), "n", 0, 10) == 7 and type(check_count(np.int32(7), "n", 0)) is int
    )


def test_a_run_writer_refuses_a_chunk_size_before_it_makes_the_file(tmp_path):
    path = tmp_path / "run.mcap"
    with pytest.raises(ValueError, match=r"chunk_size must be an integer >= 1 \(bytes\), got 0"):
        RunWriter(path, chunk_size=0)
    assert not path.exists()
