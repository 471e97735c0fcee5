# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The magnetic path of the thesis' chapters 3-5 measured against the numbers its file states
(the ``#@`` lines of data/worlds/magnetic_path.yaml): each pipe's peak at the sensor, where the
peaks lie and the longest stretch without one, the fence's cross-track slope, the road plate laid
for playback, and the outdoor odometry's along-track error over the route. And ``only_in`` on
magnetic sources: the playback field is the taught field plus exactly the marked source."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki.sim.magnetic import Dipole, DipoleLine, MagneticWorld, default_earth_field
from kiseki.sim.magnetic_lattice import DipoleLattice
from kiseki.sim.motion import WheelMotion
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"
PATH = WORLDS / "magnetic_path.yaml"


def stated(path: Path) -> dict:
    """The figures a scene file states on its ``#@`` comment lines, read as YAML."""
    lines = path.read_text(encoding="utf-8").splitlines()
    return yaml.safe_load("\n".join(ln[2:] for ln in lines if ln.startswith("#@")))


def along_path(world: MagneticWorld, height: float, y: float = 0.0):
    xs = np.round(np.arange(0.0, 118.0 + 1e-9, 0.1), 9)
    points = np.column_stack([xs, np.full_like(xs, y), np.full_like(xs, height)])
    return xs, np.linalg.norm(world.static_field_at(points) - world.earth_field, axis=1)


def peaks_of(xs: np.ndarray, d: np.ndarray, threshold: float) -> np.ndarray:
    """Positions of the local maxima of d above threshold."""
    inner = (d[1:-1] > d[:-2]) & (d[1:-1] >= d[2:]) & (d[1:-1] > threshold)
    return xs[1:-1][inner]


def measure(path: Path) -> dict:
    """The figures the file states, measured on its scene."""
    want = stated(path)
    h = want["sensor_height"]
    teach = load_scene(path)
    taught = MagneticWorld.from_dict(teach.magnetic, str(path), variant="teach")
    played = MagneticWorld.from_dict(teach.magnetic, str(path), variant="playback")
    xs, d = along_path(taught, h)
    peaks = peaks_of(xs, d, want["peak_threshold"])
    sizes = [float(d[np.abs(xs - x) <= 1.5].max()) for x, _ in want["peaks"]]
    stops = np.concatenate([[0.0], peaks, [118.0]])
    lo, hi = want["fence"]["x"]
    fx = np.arange(lo, hi + 1e-9, 0.5)
    left, right = (
        np.column_stack([fx, np.full_like(fx, y), np.full_like(fx, h)]) for y in (-0.05, 0.05)
    )
    slope = (taught.static_field_at(right) - taught.static_field_at(left))[:, 2] / 0.1
    on_path = np.column_stack([xs, 0 * xs, 0 * xs + h])
    change = played.static_field_at(on_path) - taught.static_field_at(on_path)
    return {
        "want": want,
        "peaks": peaks,
        "sizes": np.array(sizes),
        "max_gap": float(np.diff(stops).max()),
        "slope": slope,
        "change": (xs, change),
    }


@pytest.fixture(scope="module")
def path_figures():
    return measure(PATH)


def test_every_pipe_gives_the_peak_its_file_states_and_no_other_peak(path_figures):
    want, got = path_figures["want"], path_figures["sizes"]
    stated_x = np.array([x for x, _ in want["peaks"]])
    stated_size = np.array([s for _, s in want["peaks"]])
    np.testing.assert_allclose(got, stated_size, rtol=want["peak_tolerance"])
    lo, hi = want["peak_range"]
    assert np.all((got >= lo) & (got <= hi)), got
    found = path_figures["peaks"]
    assert len(found) == len(stated_x), found  # none missing, none spurious
    np.testing.assert_allclose(found, stated_x, atol=0.3)


def test_no_stretch_of_the_path_is_longer_than_stated_without_a_peak(path_figures):
    assert path_figures["max_gap"] <= path_figures["want"]["max_gap"]
    # about one disturbance every 10 m (thesis sec. 4.5.1): 118 m / 11 peaks
    assert 9.0 <= 118.0 / len(path_figures["peaks"]) <= 12.0


def test_the_fence_gives_the_stated_cross_track_slope(path_figures):
    fence, slope = path_figures["want"]["fence"], path_figures["slope"]
    np.testing.assert_allclose(slope.mean(), fence["dBz_dy"], rtol=fence["tolerance"])
    # steady along the fence: each point within the tolerance too
    np.testing.assert_allclose(slope, fence["dBz_dy"], rtol=2 * fence["tolerance"])
    # over Fig. 2.10's lines y = -1 and +1 m the difference beats the 0.01 G threshold
    assert 2.0 * slope.min() > 0.01


def test_the_road_plates_change_mz_on_the_path_over_the_thesis_region_a(path_figures):
    """Thesis sec. 4.5.1: the field's time change appears between about 10 and 25 m of travel
    (Fig. 4.7 A) and lowers every particle's likelihood alike, so it is a change of mz, the
    component the filter reads, over that whole stretch. The size the file states (0.124 G) is
    the closed form of the plates' edge under the path: a line of 33 A m^2/m pole strength 0.5 m
    below the sensor, 2e-3 x 33 / 0.5 = 0.132 G, less 0.008 G from the far edge 1.58 m away
    (its vertical part: 2e-3 x 33 / 1.58 x 0.5 / 1.58)."""
    plates = path_figures["want"]["road_plates"]
    xs, change = path_figures["change"]
    mz = change[:, 2]  # world z up
    lo, hi = plates["x"]
    closed_form = 2e-3 * 33.0 / 0.5 - 2e-3 * 33.0 / 1.5811 * 0.5 / 1.5811
    assert plates["mz"] == pytest.approx(closed_form, rel=plates["tolerance"])
    inside = (xs >= lo + 1.0) & (xs <= hi - 1.0)
    np.testing.assert_allclose(mz[inside], plates["mz"], rtol=plates["tolerance"])
    changed = xs[np.abs(mz) > 0.01]  # the thesis' disturbance threshold (sec. 3.3.2)
    assert abs(changed.min() - lo) <= plates["ends"] and abs(changed.max() - hi) <= plates["ends"]
    assert np.all(np.diff(changed) < 0.15)  # one stretch, no gap
    far = (xs < lo - 5.0) | (xs > hi + 5.0)
    assert np.linalg.norm(change[far], axis=1).max() < 0.002  # a fifth of the noise 5 m away


def test_the_playback_field_is_the_taught_field_plus_exactly_the_marked_source():
    scene_t, scene_p = load_scene(PATH, "teach"), load_scene(PATH, "playback")
    assert (scene_t.variant, scene_p.variant) == ("teach", "playback")
    section = scene_t.magnetic
    taught = MagneticWorld.from_dict(section, variant=scene_t.variant)
    played = MagneticWorld.from_dict(section, variant=scene_p.variant)
    marked = [lat for lat in section["lattices"] if lat.get("only_in") == "playback"]
    assert len(marked) == 1
    plate = DipoleLattice(**{k: v for k, v in marked[0].items() if k != "only_in"})
    points = np.random.default_rng(5).uniform([-2, -5, 0.2], [120, 5, 2.0], (400, 3))
    np.testing.assert_allclose(
        played.static_field_at(points) - taught.static_field_at(points),
        plate.field_at(points),
        rtol=1e-12,
        atol=1e-15,
    )
    # the plates' field by hand: their 360 dipoles of the closed form
    m = np.array(marked[0]["moment_mean"])
    r = points[:, None, :] - plate.positions[None]
    d = np.linalg.norm(r, axis=2)[..., None]
    by_hand = 1e-3 * ((3 * (r @ m)[..., None] * r / d**2 - m) / d**3).sum(axis=1)
    np.testing.assert_allclose(plate.field_at(points), by_hand, rtol=1e-9, atol=1e-15)


def test_only_in_on_a_dipole_and_a_line_keeps_them_out_of_the_other_variant():
    section = {
        "dipoles": [{"position": [0, 0, -1], "moment": [0, 0, 5], "only_in": "teach"}],
        "lines": [
            {"start": [2, -1, -1], "end": [2, 1, -1], "moment_per_metre": [0, 0, 3]},
            {
                "start": [4, -1, -1],
                "end": [4, 1, -1],
                "moment_per_metre": [1, 0, 0],
                "only_in": "playback",
            },
        ],
    }
    p = np.array([[0.5, 0.2, 0.5], [3.0, 0.0, 0.5], [4.2, 0.1, 0.4]])
    common = DipoleLine([2, -1, -1], [2, 1, -1], [0, 0, 3]).field_at(p)
    earth = default_earth_field()
    teach = MagneticWorld.from_dict(section, variant="teach").static_field_at(p)
    play = MagneticWorld.from_dict(section, variant="playback").static_field_at(p)
    only_teach = Dipole([0, 0, -1], [0, 0, 5]).field_at(p)
    only_play = DipoleLine([4, -1, -1], [4, 1, -1], [1, 0, 0]).field_at(p)
    np.testing.assert_allclose(teach, earth + common + only_teach, rtol=1e-12)
    np.testing.assert_allclose(play, earth + common + only_play, rtol=1e-12)
    with pytest.raises(ValueError, match=r"s\.yaml: dipoles\[0\]\.only_in: .*'teach'.*'playback'"):
        MagneticWorld.from_dict(
            {"dipoles": [dict(section["dipoles"][0], only_in="both")]}, "s.yaml"
        )
    with pytest.raises(ValueError, match="variant must be teach or playback, got 'both'"):
        MagneticWorld.from_dict(section, "s.yaml", variant="both")


def test_the_outdoor_odometry_over_counts_the_route_by_the_stated_error():
    """Many seeds of the scene's odometry over the straight route (true wheel travel 118 m each,
    in 0.3 m steps: the slip's variance is linear in the travel, so the step does not matter):
    the mean |along-track error| matches the file's figure within its 3-digit rounding plus
    5 standard errors of the mean over the seeds."""
    want = stated(PATH)["along_track"]
    scene = load_scene(PATH)
    steps = round(want["distance"] / 0.3)
    step = want["distance"] / steps
    errors = []
    for seed in range(want["seeds"]):
        odometry = build_robot(scene, seed).odometry
        motion = WheelMotion(step, step, step / 0.6)
        for _ in range(steps):
            odometry.update(motion)
        left, right = odometry.counts
        travelled = 0.5 * (left + right) * odometry.robot_params.distance_per_count
        errors.append(travelled - want["distance"])
    errors = np.abs(np.array(errors))
    tolerance = 0.0005 + 5.0 * errors.std(ddof=1) / math.sqrt(len(errors))
    assert abs(errors.mean() - want["mean_abs"]) <= tolerance, (errors.mean(), tolerance)
    # of the order of the thesis' 0.678 m without localization (Table 4.2)
    assert abs(errors.mean() - 0.678) < 0.01


def test_the_playback_scene_s_magnetometer_reads_the_playback_field():
    """build_sensors builds the field of the scene's variant: over the road plate the playback
    magnetometer reads the taught one's reading plus the plate's field."""
    readings = {}
    for variant in ("teach", "playback"):
        scene = load_scene(PATH, variant)
        sensors = build_sensors(scene, build_robot(scene, seed=0), seed=0, dt=0.1)
        (mag,) = [s.device for s in sensors if s.kind == "magnetometer"]
        readings[variant] = mag.expected((16.0, 0.0, 0.0))
    section = load_scene(PATH).magnetic
    (plate,) = [lat for lat in section["lattices"] if lat.get("only_in") == "playback"]
    b = DipoleLattice(**{k: v for k, v in plate.items() if k != "only_in"}).field_at(
        [16.0, 0.0, 0.5]
    )
    # world (x east, y north, z up) -> sensor (x forward, y right, z down) at heading 0
    np.testing.assert_allclose(
        readings["playback"] - readings["teach"], [b[0], -b[1], -b[2]], rtol=1e-9, atol=1e-12
    )
    assert np.linalg.norm(b) > 0.05
