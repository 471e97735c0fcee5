# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic navigation (thesis 002, ch. 3-4): the peak correction of the travel distance on a
synthetic peak (sec. 3.3.3), eq. 3.1's identification vector against a loop over closed-form
parallel maps, the steering sign of eq. 3.2 and eqs. 4.1-4.4 against closed forms, the priority
arbiter, the validity thresholds at their edges, the simulator's observe hook, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.apps.magnetic.navigate_run import METHODS, cross_track
from kiseki.control.arbitration import PriorityArbiter
from kiseki.control.pd_steering import PdSteering
from kiseki.magnetic.linear_map import build_linear_map, path_identity
from kiseki.magnetic.navigators import (
    MultiNavigator,
    geometric_valid,
    magnetic_valid,
    r_z,
)
from kiseki.magnetic.rahok_navigation import (
    PeakCorrection,
    RahokNavigator,
    deviation_vector,
    identification_vector,
    taught_peaks,
    weight_vector,
)

PATH = path_identity([[0.0, 0.0], [40.0, 0.0]])
MZ0 = 0.35  # G, the undisturbed vertical field (sensor z down)


def profile(s, peaks=((20.0, 0.06),), width=0.5):
    """m_z along the path: Gaussian bumps (height G, negative: a dip) on MZ0."""
    s = np.asarray(s, dtype=float)
    return MZ0 + sum(h * np.exp(-0.5 * ((s - c) / width) ** 2) for c, h in peaks)


def drive_past(corrector, offset, step=0.06, start=12.0, stop=26.0):
    """Feeds readings taken at true distances start..stop to a corrector whose estimate is
    the truth plus ``offset``; returns the final estimate minus the truth."""
    d = start + offset
    for true in np.arange(start, stop, step):
        d += corrector.update(d, float(profile(true)))
        d += step
    return d - (true + step)


@pytest.mark.parametrize("offset", [0.7, -1.3, 2.4])
def test_peak_correction_sets_the_travel_distance_to_the_taught_peak(offset):
    s = np.round(np.arange(0.0, 40.0, 0.1), 10)
    peaks = taught_peaks(s, profile(s))
    assert [(p.s, p.sign) for p in peaks] == [(20.0, 1)]
    corrector = PeakCorrection(peaks)
    error = drive_past(corrector, offset)
    ((peak_s, before, correction, height),) = corrector.log
    assert peak_s == 20.0 and before >= 23.0
    # whole 10 cm steps (sec. 3.3.3), undoing the offset to within the node spacing
    assert correction == pytest.approx(round(-offset, 1), abs=1e-9)
    assert abs(error) <= 0.05 + 1e-9
    assert height == pytest.approx(0.06, abs=0.002)


def test_a_window_peak_of_another_size_corrects_nothing():
    s = np.round(np.arange(0.0, 40.0, 0.1), 10)
    taught = taught_peaks(s, profile(s, ((20.0, 0.10),)))  # taught 0.10 G, observed 0.06 G
    corrector = PeakCorrection(taught, tolerance=0.02)
    assert drive_past(corrector, 0.7) == pytest.approx(0.7, abs=1e-9)
    assert corrector.log[0][2] is None


def test_taught_peaks_are_signed_and_one_per_window():
    s = np.round(np.arange(0.0, 60.0, 0.1), 10)
    mz = profile(s, ((10.0, 0.05), (12.0, 0.03), (30.0, -0.07), (50.0, 0.02)))
    peaks = taught_peaks(s, mz, threshold=0.04)
    assert [(p.s, p.sign, round(p.height, 3)) for p in peaks] == [(10.0, 1, 0.05), (30.0, -1, 0.07)]


def eq_3_1_loop(c, lm, rm, t):
    """Eq. 3.1 as the module reads it, one value at a time."""
    out = np.zeros(c.shape, dtype=int)
    for i in range(c.shape[0]):
        for k in range(3):
            if lm[i, k] - t > c[i, k] > rm[i, k] + t:
                out[i, k] = 1
            elif lm[i, k] + t < c[i, k] < rm[i, k] - t:
                out[i, k] = -1
    return out


def test_identification_vector_matches_eq_3_1_on_closed_form_parallel_maps():
    x = np.linspace(0.0, 30.0, 301)
    c = np.column_stack([0.2 + 0 * x, -0.05 + 0 * x, MZ0 + 0 * x])
    # left-right slope: 0 before 10 m, then 0.03 G/m across a 1 m offset, then the other way
    slope = np.where(x < 10, 0.0, np.where(x < 20, 0.03, -0.03))
    lm, rm = c.copy(), c.copy()
    lm[:, 2] += slope * 1.0
    rm[:, 2] -= slope * 1.0
    lm[:, 0] += 0.02  # x: only the left differs: no monotonic step
    s = identification_vector(c, lm, rm, 0.01)
    np.testing.assert_array_equal(s, eq_3_1_loop(c, lm, rm, 0.01))
    assert np.all(s[:, :2] == 0)
    np.testing.assert_array_equal(s[:, 2], np.where(x < 10, 0, np.where(x < 20, 1, -1)))
    # the margin is strict: a difference of exactly the threshold is no gradient
    exact = identification_vector(c[:1], c[:1] + 0.25, c[:1] - 0.25, threshold=0.25)
    assert np.all(exact == 0)


def test_weight_vector_lowers_w_theta_where_the_azimuth_changes():
    n = 200
    mt = np.where(np.arange(n) < 100, 0.3, 0.3 + 0.5)  # a 0.5 rad step at node 100
    s_vec = np.zeros((n, 3), dtype=int)
    s_vec[150:, 2] = -1
    w = weight_vector(s_vec, mt, 0.1, field_gain=20.0, theta_gain=1.0, spread0=0.05)
    assert w[20, 3] == pytest.approx(1.0) and w[100, 3] < 0.02
    np.testing.assert_array_equal(w[:, 2], np.where(np.arange(n) >= 150, 20.0, 0.0))


def test_a_robot_right_of_the_path_turns_left_with_eq_3_2():
    # the field's m_z rises to the right by 0.02 G/m: s_z = -1 by eq. 3.1
    c = np.array([[0.2, 0.0, MZ0]])
    s_vec = identification_vector(c, c - [0, 0, 0.02], c + [0, 0, 0.02])
    assert s_vec.tolist() == [[0, 0, -1]]
    w_i = np.array([20.0, 20.0, 20.0, 1.0])
    delta = 0.5  # m right of the path, heading turned 0.1 rad left (counter-clockwise)
    field = np.array([0.2 * math.cos(0.1), 0.2 * math.sin(0.1), MZ0 + 0.02 * delta])
    e = deviation_vector(c[0], 0.0, s_vec[0], w_i, field, math.atan2(field[1], field[0]))
    # closed form: s_z w_z (m_z,i - m_z,t) = -1 * 20 * -0.01 = 0.2 (turn left, towards the
    # path); m_theta = atan2(m_y, m_x) with y right grows as the robot turns left, so
    # m_theta,t = +0.1 and w_theta (m_theta,i - m_theta,t) = -0.1 (turn back right)
    np.testing.assert_allclose(e, [0.0, 0.0, 0.2, -0.1], atol=1e-12)
    pd = PdSteering(kp=0.8, kd=0.0, max_rate=1.0)
    assert pd.update(e.sum(), 0.1) == pytest.approx(0.8 * 0.1)  # > 0: turn left


def test_azimuth_sign_follows_the_heading():
    # world field (Bx, By) north-ish; a robot turned left by a (CCW) sees it at -a on its
    # right-handed (x fwd, y right) axes: m_theta = atan2(B.y_right, B.x_fwd) = a - phi
    phi, a = 0.4, 0.25
    b = np.array([math.cos(phi), math.sin(phi)])
    fwd, right = np.array([math.cos(a), math.sin(a)]), np.array([math.sin(a), -math.cos(a)])
    m_theta = math.atan2(b @ right, b @ fwd)
    assert m_theta == pytest.approx(a - phi)
    lmap = build_linear_map([0.0, 0.1], [[1.0, 0.0, MZ0]] * 2, [0.0, 0.0], path_id=PATH)
    nav = MultiNavigator(lmap, ("magnetic",), heading_gain=2.0, max_rate=5.0)
    reading = [math.cos(a), math.sin(a), MZ0]  # turned left by a in a field along x: +a
    name, w = nav.step(0, 0.0, reading, [np.nan, np.nan], 0.1)
    assert name == "magnetic" and w == pytest.approx(-2.0 * a)  # turn back right


def test_pd_derivative_and_clip():
    pd = PdSteering(kp=1.0, kd=0.5, max_rate=0.3)
    assert pd.update(0.1, 0.1) == pytest.approx(0.1)  # no derivative on the first call
    assert pd.update(0.2, 0.1) == pytest.approx(0.3)  # 0.2 + 0.5 * 1.0 = 0.7, clipped
    assert pd.update(0.2, 0.1) == pytest.approx(0.2)


def test_geometric_navigator_of_a_robot_right_of_the_path_turns_left():
    lmap = build_linear_map(
        [0.0, 0.1], [[0.2, 0.0, MZ0]] * 2, [0.0, 0.0], path_id=PATH, g=[[2.0, 2.0]] * 2
    )
    nav = MultiNavigator(lmap, ("geometric",), geometric_gain=0.3, heading_gain=1.0)
    # 0.4 m right: the left wall 0.4 m farther, the right one 0.4 m nearer; eq. 4.2
    u = nav.proposals(0, 0.0, [0.2, 0.0, MZ0], [2.4, 1.6])["geometric"][0]
    assert u == pytest.approx(0.3 * (0.4 + 0.4))


def test_arbiter_picks_the_highest_valid_priority_and_logs_it():
    arb = PriorityArbiter({"odo": 1, "geo": 2, "mag": 3, "both": 4})
    steps = [
        {"odo": ("o", True), "geo": ("g", True), "mag": ("m", True), "both": ("b", True)},
        {"odo": ("o", True), "geo": ("g", True), "mag": ("m", False), "both": ("b", False)},
        {"odo": ("o", True), "geo": ("g", False), "mag": ("m", True), "both": ("b", False)},
        {"odo": ("o", False), "geo": ("g", False), "mag": ("m", False), "both": ("b", False)},
    ]
    np.testing.assert_array_equal(arb.last_priorities(), [0, 0, 0, 0])  # before any step
    got = [arb.select(p) for p in steps[:3]]
    np.testing.assert_array_equal(arb.last_priorities(), [0, 3, 0, 1])
    got.append(arb.select(steps[3]))
    assert got == [("both", "b"), ("geo", "g"), ("mag", "m"), (None, None)]
    assert arb.history == ["both", "geo", "mag", None]
    assert arb.names == ("both", "mag", "geo", "odo")
    np.testing.assert_array_equal(
        arb.priority_history(),
        [[4, 3, 2, 1], [0, 0, 2, 1], [0, 3, 0, 1], [0, 0, 0, 0]],
    )
    assert arb.shares() == {"both": 0.25, "mag": 0.25, "geo": 0.25, "odo": 0.0, None: 0.25}


def test_multi_navigator_follows_the_thesis_priorities():
    lmap = build_linear_map(
        [0.0, 0.1], [[0.2, 0.0, MZ0]] * 2, [0.0, 0.0], path_id=PATH, g=[[2.0, 2.0]] * 2
    )
    nav = MultiNavigator(lmap)
    same, moved = [0.2, 0.0, MZ0], [0.2, 0.0, MZ0 + 0.01]
    assert nav.step(0, 0.0, same, [2.0, 2.0], 0.1)[0] == "magnetic-geometric"
    assert nav.step(0, 0.0, same, [2.0, 3.5], 0.1)[0] == "magnetic"
    assert nav.step(0, 0.0, moved, [2.0, 2.0], 0.1)[0] == "geometric"
    assert nav.step(0, 0.0, moved, [np.nan, 2.0], 0.1)[0] == "odometry"
    assert nav.arbiter.history == ["magnetic-geometric", "magnetic", "geometric", "odometry"]


def test_validity_thresholds_at_their_edges():
    assert r_z(0.35, 0.35 + 0.25) == pytest.approx(0.75)  # eq. 4.5, dm_z,max = 1 G
    assert magnetic_valid(0.35, 0.35 + 0.0019)
    assert not magnetic_valid(0.35, 0.35 + 0.0021)
    assert not magnetic_valid(0.35, 0.35 - 0.0021)
    assert magnetic_valid(0.5, 0.5 - 2.0**-9, threshold=1.0 - 2.0**-9)  # r_z == threshold
    assert geometric_valid([2.0, 3.0], [3.0, 3.0])  # exactly 1.0 m: still valid
    assert not geometric_valid([2.0, 3.0], [3.0 + 1e-9, 3.0])
    assert not geometric_valid([2.0, 3.0], [2.0, 1.99])  # the right side by 1.01 m
    assert geometric_valid([np.nan, 3.0], [np.nan, 3.5])  # one side unseen in both: used
    assert not geometric_valid([2.0, 3.0], [np.nan, 3.0])  # seen when taught, gone now
    assert not geometric_valid([np.nan, np.nan], [np.nan, np.nan])  # no landmark


def test_rahok_navigator_corrects_its_travel_distance_and_stops_at_the_end():
    s = np.round(np.arange(0.0, 30.0, 0.1), 10)
    readings = np.column_stack([0.2 + 0 * s, 0 * s, profile(s)])
    lmap = build_linear_map(s, readings, 0 * s, path_id=PATH)
    peaks = PeakCorrection(taught_peaks(lmap.s, lmap.field[:, 2]))
    zeros = np.zeros((len(lmap), 3), dtype=int)
    w = weight_vector(zeros, lmap.m_theta)
    nav = RahokNavigator(lmap, zeros, w, PdSteering(1.0), peaks)
    true = 0.0
    nav.d = 1.0  # odometry 1 m ahead
    while not nav.done:
        true += 0.06
        v, omega = nav.step(0.06, [0.2, 0.0, float(profile(true))], 0.1)
        assert omega == 0.0  # a straight field: nothing to steer
    assert peaks.log[0][2] == pytest.approx(-1.0)
    assert true == pytest.approx(lmap.s[-1], abs=0.1)
    assert v == 0.0


def test_cross_track_is_signed_left_positive():
    route = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    xt, along = cross_track(route, np.array([[5.0, 1.0], [5.0, -2.0], [11.0, 5.0], [9.0, 5.0]]))
    np.testing.assert_allclose(xt, [1.0, -2.0, -1.0, 1.0])
    np.testing.assert_allclose(along, [5.0, 5.0, 15.0, 15.0])


def test_the_simulator_gives_a_controller_odometry_and_magnetometer(tmp_path, project_data):
    from kiseki.io.runlog import read_run
    from kiseki.sim.run import SimConfig, simulate
    from kiseki.sim.scene import load_scene

    class Forward:
        seen: list = []

        def observe(self, t, odometry, readings):
            self.seen.append((t, odometry, {k: (w, v.copy()) for k, (w, v) in readings.items()}))

        def command(self, t, pose, scans):
            return 0.5, 0.0, 0.05

    ctrl = Forward()
    scene = load_scene(project_data / "worlds" / "magnetic_path.yaml")
    run = tmp_path / "r.mcap"
    simulate(scene, run, SimConfig(duration=1.0, seed=2), controller=ctrl, progress=False)
    log = read_run(run)
    odom = {round(t, 6): (m["x"], m["y"], m["theta"]) for t, m in log.messages("/odom")}
    mag = {round(t, 6): (m["x"], m["y"], m["z"]) for t, m in log.messages("/mag")}
    assert len(ctrl.seen) == 10
    for t, odometry, readings in ctrl.seen:
        np.testing.assert_allclose(odometry, odom[round(t, 6)], atol=1e-9)
        when, value = readings["mag"]
        assert when == pytest.approx(t)
        np.testing.assert_allclose(value, mag[round(t, 6)], atol=1e-9)
    assert ctrl.seen[-1][1][0] > 0.1  # the odometry moved: not the start pose each time


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PriorityArbiter({"a": 1, "b": 1}), "distinct"),
        (lambda: PriorityArbiter({"a": 0}), "finite number > 0"),
        (lambda: PriorityArbiter({}), "non-empty"),
        (lambda: PriorityArbiter({"a": 1}).select({"b": (0, True)}), r"unknown \['b'\]"),
        (lambda: PriorityArbiter({"a": 1}).select({"a": (0, "yes")}), "must be a bool"),
        (lambda: PeakCorrection([], window=3.0, check_after=3.0), "shorter than the window"),
        (lambda: PeakCorrection([]).update(float("nan"), 0.3), "d must be a finite number"),
        (lambda: taught_peaks([0, 1], [0.3]), "differ in length"),
        (
            lambda: identification_vector(np.zeros((2, 3)), np.zeros((3, 3)), np.zeros((2, 3))),
            "must all be",
        ),  # fmt: skip
        (lambda: identification_vector([[0, 0, np.nan]], [[0, 0, 0]], [[0, 0, 0]]), "NaN"),
        (lambda: PdSteering(kp=-1.0), "kp must be"),
        (lambda: PdSteering(1.0).update(float("inf"), 0.1), "finite"),
        (lambda: MultiNavigator(None, ("odometry", "bogus")), "distinct names among"),
        (lambda: geometric_valid([1.0], [1.0, 2.0]), r"\(g_l, g_r\)"),
        (
            lambda: r_z(0.3, 0.3, dmz_max=0.0),
            r"^r_z: dm_z,max must be a finite number > 0, got 0\.0$",
        ),
        (lambda: r_z(0.3, float("nan")), r"^r_z: m_z,t must be a finite number, got nan$"),
        (
            lambda: MultiNavigator(None, geometric_gain=-0.1),
            r"^MultiNavigator: geometric_gain must be a finite number >= 0, got -0\.1$",
        ),
    ],
)
def test_bad_input_is_refused(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_bad_navigation_requests_are_refused(tmp_path, project_data):
    from kiseki.apps.magnetic.navigate_run import navigate, teach

    assert METHODS == ("rahok", "magnetic-geometric", "magnetic", "geometric", "odometry", "multi")
    with pytest.raises(ValueError, match="method must be one of"):
        navigate(project_data / "worlds" / "magnetic_path.yaml", None, "lidar", tmp_path / "x")
    with pytest.raises(ValueError, match="travel must be one of odometry, peaks, filter"):
        navigate(project_data / "worlds" / "magnetic_path.yaml", None, "rahok", tmp_path / "x",
                 travel="filter")  # fmt: skip
    with pytest.raises(ValueError, match="maps must be TaughtMaps"):
        navigate(project_data / "worlds" / "magnetic_path.yaml", None, "multi", tmp_path / "x")
    for bad in (-1.0, math.nan, True):  # True was taken as an offset of 1 m
        with pytest.raises(ValueError, match="^teach: offset must be a finite number > 0 m, got "):
            teach(project_data / "worlds" / "magnetic_path.yaml", tmp_path, offset=bad)
    for bad in (0.0, math.inf, True):  # True was taken as a scale of 1
        with pytest.raises(
            ValueError, match="^navigate: gate_scale must be a finite number > 0, got "
        ):
            navigate(project_data / "worlds" / "magnetic_path.yaml", None, "multi",
                     tmp_path / "x", gate_scale=bad)  # fmt: skip
    lmap = build_linear_map([0.0, 0.1], [[0.2, 0.0, MZ0]] * 2, [0.0, 0.0], path_id=PATH)
    nav = MultiNavigator(lmap)
    with pytest.raises(ValueError, match="3 finite numbers"):
        nav.step(0, 0.0, [0.2, np.nan, MZ0], [1.0, 1.0], 0.1)
    with pytest.raises(ValueError, match=r"MultiNavigator: node must be an integer in 0..1, got "):
        nav.step(5, 0.0, [0.2, 0.0, MZ0], [1.0, 1.0], 0.1)
