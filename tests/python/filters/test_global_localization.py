# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Global localization: uniform start, spread, scan fit, and the CMU Wean Hall run 1."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from kiseki import OccupancyGrid, Pose2
from kiseki.datasets import open_scans
from kiseki.filters import (
    GlobalConfig,
    MclConfig,
    MonteCarloLocalizer,
    global_localize,
    scan_fit,
    spread_radius,
)
from kiseki.grid import FREE
from kiseki.io.ros_map import load_map
from kiseki.scans import LaserScans


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *args], capture_output=True, text=True
    )


def test_uniform_free_poses_only_on_free_cells() -> None:
    cells = np.full((40, 60), -1, dtype=np.int8)
    cells[10:20, 5:15] = 0
    cells[30:32, 40:50] = 0
    cells[12, 7] = 100
    grid = OccupancyGrid(cells, 0.1, Pose2(2.0, -1.0, 0.3))
    poses = MonteCarloLocalizer(MclConfig(), 1, grid).engine.uniform_poses(5000)
    assert poses.shape == (5000, 3)
    cell = grid.world_to_cell(poses[:, :2])
    assert (grid.cells[cell[:, 1], cell[:, 0]] == FREE).all()
    # both free regions are used in proportion to their area (100 and 20 cells)
    share = np.mean(cell[:, 1] >= 30)
    assert share == pytest.approx(20 / 119, abs=0.03)
    assert poses[:, 2].min() < -3.0 and poses[:, 2].max() > 3.0
    again = MonteCarloLocalizer(MclConfig(), 1, grid).engine.uniform_poses(5000)
    np.testing.assert_array_equal(poses, again)


def test_map_without_free_cells_is_refused() -> None:
    grid = OccupancyGrid(np.full((10, 10), 100, dtype=np.int8), 0.1)
    with pytest.raises(ValueError, match="no free cell"):
        MonteCarloLocalizer(MclConfig(), 0, grid)
    scans = LaserScans(
        times=np.zeros(1),
        poses=np.full((1, 3), np.nan),
        odometry=np.zeros((1, 3)),
        ranges=np.ones((1, 4), dtype=np.float32),
        angles=np.linspace(-1, 1, 4),
        max_range=10.0,
    )
    with pytest.raises(ValueError, match="no free cell"):
        global_localize(scans, grid, GlobalConfig(particles=10))


def test_bad_config_is_refused() -> None:
    with pytest.raises(ValueError, match="method"):
        GlobalConfig(method="odometry")
    with pytest.raises(ValueError, match="likelihood_power"):
        GlobalConfig(likelihood_power=0.0)
    with pytest.raises(ValueError, match="particle"):
        GlobalConfig(tracking_particles=0)
    with pytest.raises(ValueError, match=r"particles must be an integer in 1..10,000,000"):
        GlobalConfig(particles=2**31)  # the old code took it and failed in the engine
    with pytest.raises(ValueError, match="tracking_particles"):
        GlobalConfig(tracking_particles=2.5)


def test_spread_radius() -> None:
    poses = np.array([[0.0, 0, 0], [1.0, 0, 0], [10.0, 0, 0]])
    assert spread_radius(poses, np.array([0.5, 0.5, 0.0])) == pytest.approx(0.5)
    assert spread_radius(poses, np.array([0.45, 0.45, 0.1]), 0.9) > 0.5
    assert spread_radius(poses, np.array([1.0, 0.0, 0.0])) == 0.0


def test_scan_fit_on_a_wall() -> None:
    cells = np.zeros((50, 50), dtype=np.int8)
    cells[:, 40] = 100  # a wall at x = 4.0..4.1 m
    grid = OccupancyGrid(cells, 0.1)
    angles = np.radians(np.linspace(-20, 20, 9))
    ranges = (2.05 / np.cos(angles)).astype(np.float32)[None, :]  # sensor at x = 2 facing +x
    good = scan_fit(grid, np.array([[2.0, 2.5, 0.0]]), ranges, angles, 30.0)
    assert good.within_1_cell == 1.0 and good.mean_distance < 0.06
    bad = scan_fit(grid, np.array([[1.0, 2.5, 0.0]]), ranges, angles, 30.0)
    assert bad.within_1_cell == 0.0 and bad.mean_distance > 0.9


@pytest.fixture(scope="module")
def wean(shared_data: Path) -> tuple[Path, Path]:
    folder = shared_data / "cmu_wean"
    log, map_file = folder / "robotdata1.log.gz", folder / "wean.dat.gz"
    if not (log.is_file() and map_file.is_file()):
        pytest.skip(f"{folder}: robotdata1.log.gz or wean.dat.gz not found")
    return log, map_file


def test_wean_run1_converges_and_fits_the_map(wean: tuple[Path, Path], tmp_path: Path) -> None:
    """Run 1 through the command line, seed 0, default parameters: the cloud converges within
    the first quarter of the run, and from then on the scans fit the map far better than at
    the same estimates moved 1 m sideways or turned 10 degrees."""
    log, map_file = wean
    out = tmp_path / "run1.csv"
    done = run_cli(
        "localize", str(log), "--map", str(map_file), "--global", "-o", str(out),
        "--plot", str(tmp_path / "run1.png"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "converged at scan" in done.stdout
    doc = json.loads(out.with_suffix(".json").read_text())
    report = doc["report"]
    scans = report["scans"]
    assert scans == 713 and len(doc["spread"]) == scans
    assert report["converged"] and report["converged_scan"] < scans // 4
    fit = report["fit"]
    # 85 % measured; the share is bounded by people, open doors and unmapped rooms
    assert fit["within_1_cell"] >= 0.8
    assert fit["mean_distance"] < 0.15  # m; 10 cm cells
    for control in (report["fit_shifted_1m"], report["fit_rotated_10deg"]):
        assert control["within_1_cell"] < fit["within_1_cell"] - 0.15
        assert control["mean_distance"] > 1.8 * fit["mean_distance"]
    assert doc["particles"][0] == 50_000 and doc["particles"][-1] == 1000
    assert (tmp_path / "run1.png").stat().st_size > 10_000
    trajectory = np.loadtxt(out, delimiter=",", skiprows=1)
    assert trajectory.shape == (scans, 5)
    cells = load_map(map_file).world_to_cell(trajectory[report["converged_scan"] :, 1:3])
    assert (cells >= 0).all() and (cells < 800).all()


def test_wean_same_seed_same_trajectory(wean: tuple[Path, Path]) -> None:
    log, map_file = wean
    full = open_scans(log)
    n = 150
    scans = LaserScans(
        full.times[:n], full.poses[:n], full.odometry[:n], full.ranges[:n], full.angles,
        full.max_range,
    )  # fmt: skip
    grid = load_map(map_file)
    config = GlobalConfig(seed=7, particles=10_000)
    first = global_localize(scans, grid, config)
    second = global_localize(scans, grid, config)
    np.testing.assert_array_equal(first.estimates, second.estimates)
    np.testing.assert_array_equal(first.spread, second.spread)
    other = global_localize(scans, grid, GlobalConfig(seed=8, particles=10_000))
    assert not np.array_equal(first.estimates, other.estimates)


def test_cli_tracking_needs_reference_poses(wean: tuple[Path, Path], tmp_path: Path) -> None:
    log, map_file = wean
    done = run_cli("localize", str(log), "--map", str(map_file), "-o", str(tmp_path / "t.csv"))
    assert done.returncode == 1
    assert "no reference poses" in done.stderr and "--global" in done.stderr


def test_cli_malformed_log_names_the_line(tmp_path: Path) -> None:
    log = tmp_path / "robotdata.log"
    log.write_text("O 0 0 0 0.1\nL 0 0 0 25 0 0 100 100\n")
    map_file = tmp_path / "m.yaml"
    from kiseki.io.ros_map import save_map

    save_map(OccupancyGrid(np.zeros((10, 10), dtype=np.int8), 0.1), map_file)
    done = run_cli(
        "localize", str(log), "--map", str(map_file), "--global", "-o", str(log) + ".csv"
    )
    assert done.returncode == 1
    assert "robotdata.log:2: L line has 9 fields, expected 188" in done.stderr


def test_cli_map_convert_and_no_map_from_wean_log(wean: tuple[Path, Path], tmp_path: Path) -> None:
    log, map_file = wean
    yaml_path = tmp_path / "wean.yaml"
    done = run_cli("map", "convert", str(map_file), "-o", str(yaml_path))
    assert done.returncode == 0, done.stderr
    assert "48332 free" in done.stdout
    np.testing.assert_array_equal(load_map(yaml_path).cells, load_map(map_file).cells)
    done = run_cli("map", "from-log", str(log), "-o", str(tmp_path / "x.yaml"))
    assert done.returncode == 1 and "no reference poses" in done.stderr


def test_wean_recovery_injects_and_stays_deterministic(wean: tuple[Path, Path]) -> None:
    log, map_file = wean
    full = open_scans(log)
    n = 300
    scans = LaserScans(
        full.times[:n], full.poses[:n], full.odometry[:n], full.ranges[:n], full.angles,
        full.max_range,
    )  # fmt: skip
    grid = load_map(map_file)
    config = GlobalConfig(seed=0, recovery="augmented")
    first = global_localize(scans, grid, config)
    assert first.report.shrunk_at is not None and first.report.injected > 0
    assert first.particle_counts[-1] == config.tracking_particles
    again = global_localize(scans, grid, config)
    np.testing.assert_array_equal(first.estimates, again.estimates)
    with pytest.raises(ValueError, match="recovery"):
        GlobalConfig(recovery="pray")


def test_tracking_method_takes_over_at_the_cut(shared_data) -> None:
    """The likelihood field from a uniform start, kiseki's ray model from the cut on (Intel,
    first 400 scans, odometry as logged): up to the cut the run is the field's own, bit for bit;
    after it the estimates differ and the ray model tracks the reference poses."""
    from kiseki.datasets import read_carmen_log
    from kiseki.mapping import MapBuildConfig, map_of_log

    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans.first(400)
    grid = map_of_log(scans, MapBuildConfig(0.05))
    config = GlobalConfig(seed=3, particles=20_000, threads=1)
    field = global_localize(scans, grid, config)
    same = global_localize(
        scans, grid, GlobalConfig(**{**config.__dict__, "tracking_method": "likelihood-field"})
    )
    np.testing.assert_array_equal(same.estimates, field.estimates)  # the same model: no change
    ray = global_localize(
        scans, grid, GlobalConfig(**{**config.__dict__, "tracking_method": "ray-space-observation"})
    )
    cut = ray.report.shrunk_at
    assert cut is not None and cut == field.report.shrunk_at and cut < 100
    np.testing.assert_array_equal(ray.estimates[: cut + 1], field.estimates[: cut + 1])
    assert not np.array_equal(ray.estimates[cut + 1 :], field.estimates[cut + 1 :])
    error = np.hypot(*(ray.estimates[cut:, :2] - scans.poses[cut:, :2]).T)
    assert np.sqrt(np.mean(error**2)) < 0.15 and error.max() < 0.5  # m
    with pytest.raises(ValueError, match="tracking_method must be one of"):
        GlobalConfig(tracking_method="beam")


def test_cli_tracking_method_only_with_global(wean: tuple[Path, Path], tmp_path: Path) -> None:
    log, map_file = wean
    out = str(tmp_path / "t.csv")
    done = run_cli(
        "localize", str(log), "--map", str(map_file), "--tracking-method", "likelihood-field",
        "-o", out,
    )  # fmt: skip
    assert done.returncode == 1 and "--tracking-method applies only with --global" in done.stderr
    done = run_cli(
        "localize", str(log), "--map", str(map_file), "--global", "--tracking-method", "beam",
        "-o", out,
    )  # fmt: skip
    assert done.returncode == 1 and "tracking_method must be one of" in done.stderr
    assert "Traceback" not in done.stderr and not Path(out).exists()
