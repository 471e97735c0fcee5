# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Linear magnetic maps (thesis ch. 3-4): node averaging against a brute-force loop, m_theta of a
known field turned by a known heading, g_l / g_r in a corridor of known width, the folder round
trip, maps of another path and GP map folders refused both ways, bad input, and a short
simulated teaching run of magnetic_path against the simulator's own field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.errors import MapFormatError
from kiseki.gp import SquaredExponential
from kiseki.magnetic import (
    MagneticFieldMap,
    OtherPathError,
    build_linear_map,
    geometric_features,
    linear_map_from_run,
    load_linear_map,
    path_identity,
    save_linear_map,
)
from kiseki.magnetic.field_map import load_map_folder, save_map_folder

PATH = path_identity([[0.0, 0.0], [118.0, 0.0]])
OTHER = path_identity([[0.0, 0.0], [50.0, 5.0]])


def synthetic_samples(seed: int = 3, n: int = 400):
    """Samples with 1-6 per node, some nodes skipped (gaps of 0.25 m), angles around +-pi."""
    rng = np.random.default_rng(seed)
    steps = rng.choice([0.0, 0.02, 0.05, 0.08, 0.25], size=n, p=[0.1, 0.4, 0.3, 0.15, 0.05])
    s = 1.23 + np.cumsum(steps)
    readings = rng.normal([0.1, -0.3, 0.35], 0.05, size=(n, 3))
    readings[::7, :2] = [-0.3, 0.01]  # m_theta near pi: the unit-vector mean matters
    heading = np.pi - 0.05 + rng.normal(0.0, 0.04, n)
    g = rng.uniform(1.0, 4.0, size=(n, 2))
    g[rng.random((n, 2)) < 0.3] = np.nan
    position = np.column_stack([s, rng.normal(0.0, 0.05, n)])
    return s, readings, heading, g, position


def brute_force(s, readings, heading, g, spacing=0.1):
    """Loop version: bins of round-half-up s / spacing, means, angle means as unit vectors,
    nodes without samples interpolated between their nearest filled neighbours."""
    k = [math.floor(v / spacing + 0.5) for v in s]
    first, last = min(k), max(k)
    rows = []
    for node in range(first, last + 1):
        members = [i for i, kk in enumerate(k) if kk == node]
        if not members:
            rows.append(None)
            continue
        mt = [math.atan2(readings[i, 1], readings[i, 0]) for i in members]
        gs = []
        for c in range(2):
            vals = [g[i, c] for i in members if not math.isnan(g[i, c])]
            gs.append(sum(vals) / len(vals) if vals else math.nan)
        rows.append(
            {
                "field": [sum(readings[i, c] for i in members) / len(members) for c in range(3)],
                "u_mt": [sum(math.cos(a) for a in mt), sum(math.sin(a) for a in mt)],
                "u_th": [
                    sum(math.cos(heading[i]) for i in members),
                    sum(math.sin(heading[i]) for i in members),
                ],
                "g": gs,
                "count": len(members),
            }
        )
    filled = [i for i, r in enumerate(rows) if r is not None]
    out = []
    for i, r in enumerate(rows):
        if r is not None:
            out.append(r)
            continue
        lo = max(j for j in filled if j < i)
        hi = min(j for j in filled if j > i)
        w = (i - lo) / (hi - lo)
        a, b = rows[lo], rows[hi]
        mix = {
            key: [
                (1 - w) * x / (1 if key in ("field", "g") else a["count"])
                + w * y / (1 if key in ("field", "g") else b["count"])
                for x, y in zip(a[key], b[key], strict=True)
            ]
            for key in ("field", "u_mt", "u_th", "g")
        }
        out.append({**mix, "count": 0, "interpolated": True})
    field = np.array([r["field"] for r in out])
    m_theta = np.array([math.atan2(r["u_mt"][1], r["u_mt"][0]) for r in out])
    head = np.array([math.atan2(r["u_th"][1], r["u_th"][0]) for r in out])
    return first, field, m_theta, head, np.array([r["g"] for r in out]), [r["count"] for r in out]


def test_nodes_average_samples_like_brute_force():
    s, readings, heading, g, position = synthetic_samples()
    lmap = build_linear_map(s, readings, heading, path_id=PATH, g=g, position=position)
    first, field, m_theta, head, gg, count = brute_force(s, readings, heading, g)
    assert lmap.count.tolist() == count
    assert 0 in count and max(count) >= 3  # the data has empty and crowded nodes
    np.testing.assert_allclose(lmap.s, (first + np.arange(len(count))) * 0.1, atol=1e-12)
    np.testing.assert_allclose(lmap.field, field, atol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (lmap.m_theta - m_theta))), 0, atol=1e-12)
    np.testing.assert_allclose(np.angle(np.exp(1j * (lmap.heading - head))), 0, atol=1e-12)
    np.testing.assert_allclose(lmap.g, gg, atol=1e-12)
    assert np.isnan(lmap.g).any()


def test_m_theta_of_a_known_field_turned_by_a_known_heading():
    # world (x east, y north, z up): horizontal field at azimuth alpha; the sensor (x forward,
    # y right, z down, thesis sec. 3.3.1) on a robot of heading theta
    alpha, horizontal, up = math.radians(97.5), 0.30, -0.35
    theta = np.radians(np.arange(-180.0, 180.0, 7.5) + 0.3)
    flip = np.diag([1.0, -1.0, -1.0])
    b_world = np.array([horizontal * math.cos(alpha), horizontal * math.sin(alpha), up])
    readings = []
    for th in theta:
        rz = np.array(
            [[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0], [0, 0, 1]]
        )
        readings.append(flip @ rz.T @ b_world)
    s = np.arange(len(theta)) * 0.1
    lmap = build_linear_map(s, readings, theta, path_id=PATH)
    # closed form: m_theta = theta - alpha, i.e. theta_m = theta - m_theta = alpha (eq. 4.12)
    expected = np.angle(np.exp(1j * (theta - alpha)))
    np.testing.assert_allclose(np.angle(np.exp(1j * (lmap.m_theta - expected))), 0, atol=1e-12)
    theta_m = np.angle(np.exp(1j * (lmap.heading - lmap.m_theta)))
    np.testing.assert_allclose(theta_m, alpha, atol=1e-12)
    np.testing.assert_allclose(lmap.field[:, 2], -up, atol=1e-15)


def corridor_scan(width: float, offset: float, angles: np.ndarray, max_range: float = 30.0):
    """A laser `offset` m left of a corridor's centre line, parallel to its walls."""
    left, right = width / 2 - offset, width / 2 + offset
    sin = np.sin(angles)
    with np.errstate(divide="ignore"):
        r = np.where(sin > 0, left / sin, np.where(sin < 0, right / -sin, np.inf))
    return np.minimum(r, max_range), left, right


def test_geometric_features_in_a_corridor_of_known_width():
    angles = np.radians(np.arange(-135.0, 135.01, 0.25))
    ranges, left, right = corridor_scan(3.0, 0.4, angles)
    np.testing.assert_allclose(geometric_features(ranges, angles, 30.0), [left, right], atol=1e-12)
    # a post at 70 deg, 1 m away, is in the left window (60..120 deg); one at 50 deg is not
    post = ranges.copy()
    post[np.argmin(np.abs(angles - math.radians(70)))] = 1.0
    post[np.argmin(np.abs(angles - math.radians(50)))] = 0.5
    g = geometric_features(post, angles, 30.0)
    np.testing.assert_allclose(g, [math.sin(math.radians(70)), right], atol=1e-12)
    # a window too short for the walls, and no return at all: no feature
    short = geometric_features(ranges, angles, 30.0, window_range=(left + right) / 2)
    assert short[0] == pytest.approx(left) and np.isnan(short[1])
    assert np.isnan(geometric_features(np.full(angles.shape, 30.0), angles, 30.0)).all()
    many = geometric_features(np.stack([ranges, post]), angles, 30.0)
    assert many.shape == (2, 2) and many[1, 0] == pytest.approx(g[0])
    # a scan of no beam is no scan (it gave NaN features, as if the windows saw nothing)
    with pytest.raises(ValueError, match=r"^geometric_features: the scan has no beams$"):
        geometric_features(np.zeros(0), np.zeros(0), 30.0)


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        ({"max_range": 0.0}, r"max_range must be a finite number > 0 m, got 0\.0$"),
        ({"max_range": True}, r"max_range must be a finite number > 0 m, got True$"),  # was 1 m
        ({"window_range": np.nan}, r"window_range must be a finite number > 0 m, got nan$"),
        ({"window_range": True}, r"window_range must be .* m, got True$"),  # was 1 m
        ({"window_angle": 4.0}, r"window_angle must be a finite number in \(0, pi\] rad"),
        ({"window_angle": True}, r"window_angle must be .* rad, got True$"),  # was 1 rad
    ],
)
def test_geometric_features_bad_settings_are_refused(kw, message):
    angles = np.radians(np.arange(-135.0, 135.01, 15.0))
    kw = {"max_range": 30.0, **kw}
    with pytest.raises(ValueError, match="^geometric_features: " + message):
        geometric_features(np.ones(angles.shape), angles, **kw)


def test_lookup_nearest_and_interpolated():
    s = [0.0, 0.1, 0.2]
    readings = [[0.0, 1.0, 0.1], [0.0, 1.0, 0.3], [0.0, 1.0, 0.5]]
    heading = np.radians([179.0, -179.0, -170.0])
    lmap = build_linear_map(s, readings, heading, path_id=PATH)
    assert lmap.index(0.149) == 1 and lmap.index(0.151) == 2 and lmap.index(-5.0) == 0
    # far beyond the ends: the end nodes (1e20 m wrapped through int64 to node 0)
    assert lmap.index(1e20) == 2 and lmap.index(-1e300) == 0 and lmap.index(1e300) == 2
    values = lmap.at([0.05, 0.15, 9.0])
    np.testing.assert_allclose(values.field[:, 2], [0.2, 0.4, 0.5], atol=1e-12)
    assert abs(np.angle(np.exp(1j * (values.heading[0] - math.pi)))) < 1e-12  # across +-pi
    with pytest.raises(ValueError, match="NaN"):
        lmap.at(math.nan)


def test_save_load_round_trip_is_exact(tmp_path):
    s, readings, heading, g, position = synthetic_samples(seed=5)
    lmap = build_linear_map(
        s, readings, heading, path_id=PATH, g=g, position=position, provenance={"run": "x"}
    )
    folder = save_linear_map(lmap, tmp_path / "map")
    back = load_linear_map(folder, path_id=PATH)
    for name in ("s", "field", "m_theta", "heading", "g", "count", "position"):
        assert np.array_equal(getattr(back, name), getattr(lmap, name), equal_nan=True), name
    assert (back.spacing, back.path_id, dict(back.provenance)) == (0.1, PATH, {"run": "x"})
    assert back.window == pytest.approx(lmap.window)
    save_linear_map(back, folder)  # a linear map folder is replaced
    with pytest.raises(OtherPathError, match=f"path {PATH}, not of this path {OTHER}"):
        load_linear_map(folder, path_id=OTHER)


def small_gp_map() -> MagneticFieldMap:
    shape = (2, 3, 4, 3)
    return MagneticFieldMap(
        origin=[0.0, 0.0, 0.0],
        resolution=0.5,
        mean=np.ones(shape),
        variance=np.ones(shape),
        prior_mean=[0.0, 0.0, 0.0],
        prior_variance=[1.0, 1.0, 1.0],
        kernel=SquaredExponential(1.0, 0.5, 0.1),
        units="G",
    )


def test_gp_and_linear_map_folders_refuse_each_other(tmp_path):
    gp = save_map_folder(small_gp_map(), tmp_path / "gp")
    with pytest.raises(MapFormatError, match="a GP magnetic map .*, not a linear one"):
        load_linear_map(gp)
    with pytest.raises(MapFormatError, match="a GP magnetic map"):
        save_linear_map(build_linear_map([0.0], [[0.1, 0.2, 0.3]], [0.0], path_id=PATH), gp)
    linear = save_linear_map(
        build_linear_map([0.0], [[0.1, 0.2, 0.3]], [0.0], path_id=PATH), tmp_path / "lin"
    )
    with pytest.raises(MapFormatError, match="a linear magnetic map .*, not a GP one"):
        load_map_folder(linear)
    with pytest.raises(FileExistsError):
        save_map_folder(small_gp_map(), linear)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("x")
    with pytest.raises(FileExistsError, match="not a linear magnetic map folder"):
        save_linear_map(
            build_linear_map([0.0], [[0.1, 0.2, 0.3]], [0.0], path_id=PATH), tmp_path / "other"
        )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"s": [], "readings": np.empty((0, 3)), "heading": []}, "no samples"),
        ({"readings": [[0.1, 0.2, 0.3], [0.1, math.nan, 0.3], [0.1, 0.2, 0.3]]}, r"readings\[1\]"),
        ({"heading": [0.0, 0.0, math.inf]}, r"heading\[2\]"),
        ({"spacing": 0.0}, r"spacing must be a finite number > 0 m, got 0\.0$"),
        ({"spacing": -0.1}, r"spacing must be a finite number > 0 m, got -0\.1$"),
        ({"tolerance": math.nan}, r"tolerance must be a finite number >= 0 m, got nan$"),
        ({"tolerance": True}, r"tolerance must be a finite number >= 0 m, got True$"),  # was 1 m
        ({"s": [0.0, 0.5, 0.2]}, r"not monotonic: s\[2\]"),
        ({"path_id": "abc"}, "path_id must be 40 hex digits"),
        ({"readings": [[0.1, 0.2, 0.3]] * 2}, r"readings has shape \(2, 3\)"),
        # a float window was "'float' object is not subscriptable", (-1, 0) was taken, and s of
        # 1e300 m overflowed the node indices ("'list' argument must have no negative ...")
        ({"window": 1.0}, r"window must be \(range m > 0, full angle .*, got 1\.0$"),
        ({"window": (-1.0, 0.0)}, r"window must be .*, got \(-1\.0, 0\.0\)$"),
        ({"window": (10.0, 4.0)}, r"window must be .* in \(0, pi\] rad"),
        ({"s": [0.0, 1e300, 2e300]}, r"2e\+301 nodes is over the limit of 10,000,000$"),
    ],
)
def test_bad_input_is_refused(change, message):
    args = {
        "s": [0.0, 0.05, 0.1],
        "readings": [[0.1, 0.2, 0.3]] * 3,
        "heading": [0.0, 0.0, 0.0],
        "path_id": PATH,
    }
    args.update(change)
    with pytest.raises(ValueError, match=message):
        build_linear_map(args.pop("s"), args.pop("readings"), args.pop("heading"), **args)


def test_monotonic_tolerance():
    lmap = build_linear_map([0.0, 0.1, 0.1 - 5e-7], [[0, 1, 0]] * 3, [0, 0, 0], path_id=PATH)
    assert lmap.count.tolist() == [1, 2]


def test_simulated_teaching_run_matches_the_simulator_field(tmp_path, project_data):
    from kiseki.sim.run import SimConfig, simulate
    from kiseki.sim.scene import load_scene
    from kiseki.sim.setup import build_robot, build_sensors

    scene = load_scene(project_data / "worlds" / "magnetic_path.yaml")
    run = tmp_path / "teach.mcap"
    simulate(scene, run, SimConfig(duration=30.0, seed=4), progress=False)
    path_id = path_identity(scene.route["waypoints"])
    lmap = linear_map_from_run(run, path_id)
    assert lmap.path_id == PATH
    assert len(lmap) > 150 and lmap.s[0] == 0.0
    np.testing.assert_allclose(np.diff(lmap.s), 0.1, atol=1e-12)
    filled = lmap.count > 0
    # odometry's 0.1 m of travel are 0.1 m of true travel along the straight path
    assert np.median(np.diff(lmap.position[filled, 0])) == pytest.approx(0.1, abs=0.01)
    sensor = next(
        x for x in build_sensors(scene, build_robot(scene, 4), 4, 0.1) if x.kind == "magnetometer"
    )
    device = sensor.device
    poses = np.column_stack([lmap.position[filled], np.zeros(filled.sum())])
    truth = device.expected_many(poses, np.zeros(filled.sum()))
    sigma = device.noise_sd / np.sqrt(lmap.count[filled])
    z = (lmap.field[filled, 2] - truth[:, 2]) / sigma
    assert np.abs(z).max() < 4.5
    assert 0.7 < np.mean(z**2) < 1.35  # the averaging divides the noise variance by the count
    # the walls 3.85 m either side until x = 20 m (the minimum of noisy beams reads a bit short)
    np.testing.assert_allclose(lmap.g[filled][lmap.position[filled, 0] < 15], 3.8, atol=0.1)


def test_a_nodes_file_cut_short_is_refused_naming_it(tmp_path):
    lmap = build_linear_map([0.0, 0.1, 0.2], [[0.1, 0.2, 0.3]] * 3, [0, 0, 0], path_id=PATH)
    folder = save_linear_map(lmap, tmp_path / "map")
    nodes = folder / "nodes.npz"
    data = nodes.read_bytes()
    assert data[:2] == b"PK" and len(data) > 200
    nodes.write_bytes(data[: len(data) // 2])  # a copy that stopped half way
    with pytest.raises(ValueError, match="not a readable .npz file") as caught:
        load_linear_map(folder)
    assert str(caught.value).startswith(str(nodes)) and "\n" not in str(caught.value)


def test_a_field_beyond_the_bound_of_every_number_is_refused(tmp_path):
    """A node's field of 1e300 was navigated on (3.18 m off the path instead of 0.33 m)."""
    lmap = build_linear_map([0.0, 0.1, 0.2], [[0.1, 0.2, 0.3]] * 3, [0, 0, 0], path_id=PATH)
    folder = save_linear_map(lmap, tmp_path / "map")
    nodes = folder / "nodes.npz"
    with np.load(nodes) as npz:
        arrays = dict(npz)
    arrays["field"][1, 2] = 1e300
    np.savez(nodes, **arrays)
    with pytest.raises(MapFormatError) as caught:
        load_linear_map(folder)
    assert str(caught.value) == f"{nodes}: 'field' holds 1e+300, beyond +-1e+09"
    arrays["field"][1, 2] = 1e9  # the bound itself is a number a file may hold
    np.savez(nodes, **arrays)
    assert load_linear_map(folder).field[1, 2] == 1e9


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("nodes: 3", "nodes: 4"), r"nodes\.npz: 's' is float64 \(3,\), expected \(4,\)"),
        (("units: G", "units: uT"), r"linear_map\.yaml: units: must be 'G'"),
        (("node_spacing: 0.1", "node_spacing: -0.1"), "node_spacing: must be greater than 0"),
        (("first_node_s: 0.0", "first_node_s: 1.0"), "'s' disagrees with first_node_s"),
        (("kind: linear_magnetic_map", "kind: magnetic_field_map"), "a GP magnetic map"),
        (("files:", "colour: red\nfiles:"), "colour: unknown key"),
    ],
)
def test_malformed_folder_is_refused(tmp_path, edit, message):
    lmap = build_linear_map([0.0, 0.1, 0.2], [[0.1, 0.2, 0.3]] * 3, [0, 0, 0], path_id=PATH)
    folder = save_linear_map(lmap, tmp_path / "map")
    meta = folder / "linear_map.yaml"
    text = meta.read_text()
    assert edit[0] in text
    meta.write_text(text.replace(edit[0], edit[1]))
    with pytest.raises(ValueError, match=message):
        load_linear_map(folder)


def test_path_identity_tells_paths_apart_and_refuses_points_beyond_its_millimetres():
    """Points in whole millimetres as int64: 1e17 and 2e17 m wrapped to one identity."""
    assert path_identity([[0.0, 0.0], [1.0, 0.0]]) == path_identity([[0.0, 0.0], [1.0004, 0.0]])
    assert path_identity([[0.0, 0.0], [1.0, 0.0]]) != path_identity([[0.0, 0.0], [1.001, 0.0]])
    for far in (1e17, 2e17, -1e10):
        with pytest.raises(ValueError, match="beyond \\+-1e9 m"):
            path_identity([[far, 0.0]])
