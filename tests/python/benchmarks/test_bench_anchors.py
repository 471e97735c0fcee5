# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""benchmarks/bench_anchors.py's harnesses (benchmarks/anchors/): the input file the Python side
writes is the one each C++ harness reads (a byte-exact round trip through the C++ reader and
writer), the kiseki harness drives kiseki's engine exactly as kiseki.filters.localize does, and
on the first 60 scans of the Intel log nav2, beluga and kiseki all track the reference from a
known start where the odometry alone drifts metres away.

Skips when the anchors' sources (../shared/anchors) are absent. The harnesses are built in
build/anchors as the benchmark builds them (a cold build compiles kiseki_core and the anchors,
minutes; later runs reuse it).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import anchors_harness as ah  # noqa: E402
from amcl_inputs import (  # noqa: E402
    INITIAL_SD,
    SIGMA_HIT,
    Z_HIT,
    Z_RAND,
    load_log,
    log_odometry,
    select_scans,
)
from bench_anchors import harness_input, kiseki_engine_seed, main  # noqa: E402
from kiseki.filters import LocalizeConfig, localize  # noqa: E402
from kiseki.metrics import ape  # noqa: E402

SCANS = 60
PARTICLES = 200
BEAMS = 60
# Every library's position RMSE over the first 60 scans stays below this, where the noisy
# odometry's alone is over three times it (checked, so that a filter ignoring its scans fails)
TRACKING_RMSE = 0.6  # m


@pytest.fixture(scope="module")
def harnesses() -> dict[str, Path]:
    if not ah.anchors_present(ah.ANCHORS):
        pytest.skip(f"the anchors' sources are not at {ah.ANCHORS} (../shared/anchors)")
    return ah.build(ah.ANCHORS)


@pytest.fixture(scope="module")
def intel(shared_data):
    inputs = load_log("intel", shared_data)
    odometry = log_odometry(inputs, 0)
    return inputs, odometry, select_scans(inputs.scans, odometry, BEAMS, SCANS)


def synthetic_input(rng: np.random.Generator) -> ah.HarnessInput:
    ranges = rng.uniform(0.1, 30.0, (7, 5)).astype(np.float32)
    ranges[2, 3] = np.nan
    return ah.HarnessInput(
        cells=rng.choice(np.array([-1, 0, 100], dtype=np.int8), (4, 6)),
        resolution=0.05,
        origin=(-1.25, 3.5),
        max_range=30.0,
        angles=np.linspace(-1.5, 1.5, 5),
        ranges=ranges,
        odometry=rng.normal(size=(7, 3)),
        parameters={name: float(k) + 0.5 for k, name in enumerate(ah.PARAMETERS)},
    )


def test_input_round_trip(harnesses, tmp_path):
    data = synthetic_input(np.random.default_rng(3))
    path = tmp_path / "input.bin"
    ah.write_input(path, data)
    back = ah.read_input(path)
    np.testing.assert_array_equal(back.cells, data.cells)
    np.testing.assert_array_equal(back.ranges, data.ranges)
    np.testing.assert_array_equal(back.odometry, data.odometry)
    np.testing.assert_array_equal(back.angles, data.angles)
    assert (back.resolution, back.origin, back.max_range) == (0.05, (-1.25, 3.5), 30.0)
    assert back.parameters == data.parameters
    for name, exe in harnesses.items():
        copy = tmp_path / f"{name}.bin"
        ah.echo_input(exe, path, copy)
        assert copy.read_bytes() == path.read_bytes(), name


def test_harness_refuses_a_truncated_input(harnesses, tmp_path):
    path = tmp_path / "input.bin"
    ah.write_input(path, synthetic_input(np.random.default_rng(4)))
    path.write_bytes(path.read_bytes()[:-8])
    with pytest.raises(ah.HarnessError, match="ends inside the odometry"):
        ah.run_harness(harnesses["nav2_harness"], path, tmp_path / "out.bin", 10, 0)


def test_kiseki_harness_is_kiseki_localize(harnesses, intel, tmp_path):
    """The C++ harness and the Python API give the same estimates for the same seed."""
    inputs, _, scans = intel
    path = tmp_path / "input.bin"
    ah.write_input(path, harness_input(scans, inputs.grid, inputs.alphas))
    for combination in ("nav2", "product"):
        estimates, seconds = ah.run_harness(
            harnesses["kiseki_harness"], path, tmp_path / "out.bin", PARTICLES,
            kiseki_engine_seed(0), combination=combination,
        )  # fmt: skip
        config = LocalizeConfig(
            method="likelihood-field", seed=0, particles=PARTICLES, beams=0,
            alphas=inputs.alphas, initial_sd=INITIAL_SD, sigma_hit=SIGMA_HIT, z_hit=Z_HIT,
            z_rand=Z_RAND, combination=combination, kld=False, resampling="multinomial",
            resample_threshold=1.0, recovery="none", update_min_d=0.0, update_min_a=0.0,
            threads=1,
        )  # fmt: skip
        expected = localize(scans, inputs.grid, config).estimates
        np.testing.assert_allclose(estimates, expected, atol=1e-6)
        assert seconds.shape == (SCANS,) and (seconds > 0).all()


def test_all_three_track_the_start_of_intel(harnesses, intel, tmp_path):
    inputs, odometry, scans = intel
    assert ape(odometry[:SCANS], scans.poses).rmse > 3 * TRACKING_RMSE
    path = tmp_path / "input.bin"
    ah.write_input(path, harness_input(scans, inputs.grid, inputs.alphas))
    for name in ah.HARNESSES:
        seed = kiseki_engine_seed(0) if name == "kiseki_harness" else 0
        estimates, _ = ah.run_harness(harnesses[name], path, tmp_path / "out.bin", PARTICLES, seed)
        assert estimates.shape == (SCANS, 3)
        assert ape(estimates, scans.poses).rmse < TRACKING_RMSE, name


def test_kiseki_harness_gives_one_result_for_any_thread_count(harnesses, intel, tmp_path):
    inputs, _, scans = intel
    path = tmp_path / "input.bin"
    ah.write_input(path, harness_input(scans, inputs.grid, inputs.alphas))
    # 600 particles: kiseki splits its loops in chunks of at least 256, so two threads share them
    runs = [
        ah.run_harness(harnesses["kiseki_harness"], path, tmp_path / "out.bin", 600, 7, threads=t)[
            0
        ]
        for t in (1, 2)
    ]
    np.testing.assert_array_equal(runs[0], runs[1])


def test_bench_skips_without_the_anchors(tmp_path, capsys):
    assert main(["--anchors", str(tmp_path), "--quick"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and "skipped" in out[0]
