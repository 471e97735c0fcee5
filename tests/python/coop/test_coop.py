# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning: triangulation against the paper's closed forms (eqs. 1-4), against
Monte Carlo on random geometry, in 3-D against 2-D, and its refusals of bad geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import paper_error, paper_position, triangulate

SIGMA = math.radians(0.1)  # the paper's bearing noise


@pytest.mark.parametrize("theta1", [0.35, 0.785, 1.1])
@pytest.mark.parametrize("theta2", [0.5, 0.785, 1.3])
def test_symmetric_case_matches_equations_1_to_4(theta1: float, theta2: float) -> None:
    d = 1.5
    standing = [[-d, 0.0], [d, 0.0]]
    bearings = [theta1, math.pi - theta2]  # robot 1 sees theta1 from +x, robot 2 from -x
    position, covariance = triangulate(standing, bearings, bearing_sigma=SIGMA)
    np.testing.assert_allclose(position, paper_position(d, theta1, theta2), atol=1e-12)
    jac = np.column_stack(
        [paper_error(d, theta1, theta2, 1.0, 0.0), paper_error(d, theta1, theta2, 0.0, 1.0)]
    )
    np.testing.assert_allclose(covariance, SIGMA**2 * jac @ jac.T, rtol=1e-9, atol=1e-18)


def test_equation_3_as_printed_contradicts_equation_1() -> None:
    d, t1, t2, h = 1.0, 0.6, 1.0, 1e-7
    numeric = (paper_position(d, t1 + h, t2) - paper_position(d, t1 - h, t2)) / (2 * h)
    np.testing.assert_allclose(paper_error(d, t1, t2, 1.0, 0.0), numeric, rtol=1e-6)
    s2 = math.sin(t1 + t2) ** 2
    printed_dx = d * math.sin(2 * t2) / s2  # eq. 3 as printed, dth1 = 1, dth2 = 0
    assert printed_dx == pytest.approx(-numeric[0], rel=1e-6)  # the sign is the misprint
    # sec. 3.2: opposite errors make the cross-track error (x), equal ones none on the centre line
    assert abs(paper_error(d, 0.8, 0.8, 1.0, -1.0)[0]) > 1.0
    assert paper_error(d, 0.8, 0.8, 1.0, 1.0)[0] == pytest.approx(0.0, abs=1e-12)


def _bearings(standing: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = target - standing
    return np.arctan2(d[:, 1], d[:, 0]), np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))


def test_covariance_matches_monte_carlo_in_3d() -> None:
    rng = np.random.default_rng(5)
    standing = np.array([[0.0, 0.0, 0.0], [4.0, 0.5, 0.4], [1.0, 5.0, -0.3]])
    target = np.array([2.5, 2.0, 1.0])
    bearings, elevations = _bearings(standing, target)
    sigma = math.radians(0.5)
    position, covariance = triangulate(
        standing, bearings, elevations, bearing_sigma=sigma, elevation_sigma=2 * sigma
    )
    np.testing.assert_allclose(position, target, atol=1e-9)
    samples = np.array(
        [
            triangulate(
                standing,
                bearings + rng.normal(0, sigma, 3),
                elevations + rng.normal(0, 2 * sigma, 3),
                bearing_sigma=sigma,
                elevation_sigma=2 * sigma,
            )[0]
            for _ in range(4000)
        ]
    )
    sample_cov = np.cov(samples.T)
    assert np.linalg.norm(sample_cov - covariance) < 0.08 * np.linalg.norm(covariance)


def test_three_d_on_a_plane_is_two_d() -> None:
    standing = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]])
    target = np.array([1.0, 1.5])
    b = np.arctan2(target[1] - standing[:, 1], target[0] - standing[:, 0])
    p2, c2 = triangulate(standing, b + [0.001, -0.002, 0.0015], bearing_sigma=SIGMA)
    flat = np.column_stack([standing, np.zeros(3)])
    p3, c3 = triangulate(flat, b + [0.001, -0.002, 0.0015], np.zeros(3), bearing_sigma=SIGMA)
    np.testing.assert_allclose(p3[:2], p2, atol=1e-12)
    np.testing.assert_allclose(c3[:2, :2], c2, rtol=1e-9)
    assert p3[2] == pytest.approx(0.0, abs=1e-12)
    assert triangulate(standing, b).shape == (2,)


@pytest.mark.parametrize(
    ("standing", "bearings", "message"),
    [
        ([[0.0, 0.0]], [0.3], "at least two standing robots"),
        ([[1.0, 2.0], [1.0, 2.0]], [0.3, 1.2], "coincide"),
        ([[0.0, 0.0], [1.0, 0.0]], [0.3, float("nan")], "bearing 1 is not finite"),
        ([[0.0, 0.0], [1.0, 0.0]], [0.3], "2 standing robots but 1 bearings"),
        ([[-1.0, 0.0], [1.0, 0.0]], [math.pi / 2, math.pi / 2 + 0.005], "nearly parallel"),
        ([[-1.0, 0.0], [1.0, 0.0]], [0.0, math.pi], "nearly parallel"),  # on the baseline
        ([[1.0, 0.0], [-1.0, 0.0]], [-math.pi / 4, -3 * math.pi / 4], "points away"),
        ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [0.3, 1.0], "shape (n, 2)"),
        ([["a", "b"], ["c", "d"]], [0.3, 1.0], "standing"),
    ],
)
def test_bad_geometry_and_input_are_named(standing, bearings, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        triangulate(standing, bearings)


def test_bad_sigma_and_paper_angles() -> None:
    with pytest.raises(ValueError, match="bearing_sigma"):
        triangulate([[-1.0, 0.0], [1.0, 0.0]], [0.8, 2.3], bearing_sigma=-1.0)
    with pytest.raises(ValueError, match="elevation 0"):
        triangulate([[0.0, 0, 0], [1.0, 0, 0]], [0.5, 2.0], [math.pi / 2, 0.0])
    with pytest.raises(ValueError, match="interior angles"):
        paper_position(1.0, 2.0, 1.5)
    with pytest.raises(ValueError, match="nearly parallel"):
        paper_position(1.0, 1e-4, 1e-4)


# --- the positioning loop and the movement forms ---

from kiseki.coop import GOAL, START, paper_angle, plan, simulate  # noqa: E402


def _angle_at(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    u, v = a - p, b - p
    return math.acos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1))


def test_form_1_measures_the_scout_symmetrically_and_takes_two_moves_per_unit() -> None:
    angle = math.radians(55)
    p = plan(1, 15, angle)
    assert len(p.steps) == 15 and np.allclose(p.steps[-1].target, GOAL)
    at = p.nominal_positions()
    levels = []
    for k, move in enumerate(p.steps[:-1]):
        i, j = move.standing
        before = at[k]
        if k % 2 == 0:  # the scout: both standing robots see it at the angle (theta1 = theta2)
            assert before[i, 1] == pytest.approx(before[j, 1])  # a lateral pair
            assert _angle_at(before[i], before[j], move.target) == pytest.approx(angle)
            assert _angle_at(before[j], before[i], move.target) == pytest.approx(angle)
        else:  # the joiner lands level with the scout: the next pair
            assert move.target[1] == pytest.approx(at[k + 1][p.steps[k - 1].robot][1])
            levels.append(move.target[1])
    rise = np.diff([0.0, *levels])  # the first over the start's baseline: w = 1 m
    assert rise[0] == pytest.approx(math.tan(angle))
    np.testing.assert_allclose(rise[1:], rise[1])  # then 2 moves per unit of forward travel
    assert levels[-1] + rise[1] == pytest.approx(GOAL[1])


def test_form_2_leapfrogs_one_unit_per_move_on_isosceles_triangles() -> None:
    angle = math.radians(50)
    p = plan(2, 9, angle)
    at = p.nominal_positions()
    ys = [m.target[1] for m in p.steps]
    np.testing.assert_allclose(np.diff(ys), GOAL[1] / 9)  # 1 move per unit
    for k, move in enumerate(p.steps[2:-1], start=2):
        before = at[k]
        assert move.robot == int(np.argmin(before[:, 1]))  # the rearmost jumps
        far = max(move.standing, key=lambda r: np.hypot(*(before[r] - move.target)))
        near = move.standing[0] if far == move.standing[1] else move.standing[1]
        assert _angle_at(before[far], before[near], move.target) == pytest.approx(angle)


def test_paper_angle_keeps_the_start_width() -> None:
    for form, n in ((1, 9), (2, 7)):
        p = plan(form, n)
        assert p.angle == pytest.approx(paper_angle(form, n))
        xs = np.abs(p.nominal_positions()[:, :, 0])
        assert xs.max() == pytest.approx(2.0 if form == 1 else 1.0)  # widths follow the start's


def test_simulation_is_seeded_and_its_error_scales_with_the_noise() -> None:
    p = plan(2, 7)
    a, b = simulate(p, 200, seed=4), simulate(p, 200, seed=4)
    np.testing.assert_array_equal(a.goal_errors, b.goal_errors)
    assert not np.array_equal(a.goal_errors, simulate(p, 200, seed=5).goal_errors)
    assert simulate(p, 10, angle_sigma=0.0).goal_errors.max() < 1e-9  # exact without noise
    # first order: ten times the noise, ten times the error (same draws)
    small = simulate(p, 500, angle_sigma=math.radians(0.01), seed=9).goal_errors
    large = simulate(p, 500, angle_sigma=math.radians(0.1), seed=9).goal_errors
    assert large.mean() / small.mean() == pytest.approx(10.0, rel=0.01)


def test_errors_accumulate_along_the_chain() -> None:
    run = simulate(plan(2, 12), 400, seed=2)
    spread = [
        np.sqrt(np.trace(np.cov(run.estimates[:, k + 1, m.robot].T)))
        for k, m in enumerate(run.plan.steps)
    ]
    assert spread[-1] > 2 * spread[0]
    assert np.allclose(run.estimates[:, 0], START)  # the start is measured beforehand


def test_bad_plans_are_refused() -> None:
    with pytest.raises(ValueError, match="form must be 1 or 2"):
        plan(3, 5, 0.9)
    with pytest.raises(ValueError, match="odd number of moves"):
        plan(1, 4, 0.9)
    with pytest.raises(ValueError, match="5..85 deg"):
        plan(2, 5, math.radians(89))
    with pytest.raises(ValueError, match="ahead"):
        plan(2, 5, 0.9, goal=(0.0, -5.0))
    with pytest.raises(ValueError, match="start: expected 3"):
        plan(2, 5, start=[[0.0, 0.0]])
    with pytest.raises(ValueError, match="numbers"):
        plan(2, 5, goal=("a", 1))
    with pytest.raises(ValueError, match="runs"):
        simulate(plan(2, 5), 0)
    with pytest.raises(ValueError, match="seed"):
        simulate(plan(2, 5), 5, seed=-1)


def test_coop_experiment_claims_and_cli(tmp_path) -> None:
    import subprocess
    import sys

    import pandas as pd

    from kiseki_experiments.harness.runner import run_experiment

    small = ["form1_moves=3,5,7,9", "form2_moves=5,7", "angles_deg=45,55"]
    with pytest.raises(ValueError, match="22 settings"):  # 4 x 2 + 2 moves, 2 x 3 angles, 6
        run_experiment(
            "coop-forms",
            runs=23,
            overrides=small,
            out=tmp_path / "too_many",
            progress=False,
        )
    run = run_experiment(
        "coop-forms",
        seed=0,
        overrides=[*small, "dead_reckoning_runs=50"],
        out=tmp_path / "c",
        progress=False,
    )
    assert run.failed == 0
    claims = pd.read_csv(run.run_dir / "claims.csv").set_index("claim")
    lower = claims.filter(like="lower minimum", axis=0)
    assert len(lower) == 2  # each reading of form 1 against form 2
    table = pd.read_csv(run.run_dir / "tables" / "sweep.csv")
    assert set(table["form"]) == {1, 2} and len(table) == 10
    angles = pd.read_csv(run.run_dir / "tables" / "angle_sweep.csv")
    assert sorted(angles["angle_deg"].round(6).unique()) == [45.0, 55.0] and len(angles) == 6
    # the crossing reading's weakest triangle is wider than pair and scout's at every angle
    sight = angles[angles["form"] == 1].pivot(index="angle_deg", columns="reading",
                                              values="min_sight_angle_deg")  # fmt: skip
    assert (sight["crossing"] > sight["pair-scout"]).all()
    assert (table["mean_error_m"] > 0).all() and (table["mean_error_m"] < 1.0).all()
    dead = pd.read_csv(run.run_dir / "tables" / "dead_reckoning.csv")
    assert dead["mean_error_m"].iloc[0] > table["mean_error_m"].min()
    planner = pd.read_csv(run.run_dir / "tables" / "planner.csv")
    # the planner beats pair and scout and form 2; the crossing reading of form 1 can beat it
    first = table[table["reading"].fillna("") != "crossing"]
    assert planner["predicted_rms_m"].iloc[0] < first["predicted_rms_m"].min()
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--form", "2", "--moves", "7",
         "--runs", "50", "--plot", str(tmp_path / "g.png")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "error at the goal mean" in done.stdout and (tmp_path / "g.png").stat().st_size > 5000
    bad = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--form", "1", "--moves", "4"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert bad.returncode == 1 and bad.stderr.startswith("kiseki: error: form 1 takes an odd")
    both = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--planner", "--moves", "5"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert both.returncode == 1 and "--planner chooses the moves itself" in both.stderr
    chosen = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--planner", "--runs", "20"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert chosen.returncode == 0 and chosen.stdout.startswith("planner, 5 moves")


# --- first-order prediction and the move planner ---

from kiseki.coop.planner import plan_moves, predict, predicted_goal_rms  # noqa: E402


@pytest.mark.parametrize(("form", "moves"), [(1, 5), (1, 15), (2, 7), (2, 20)])
def test_predicted_covariance_matches_monte_carlo(form: int, moves: int) -> None:
    p = plan(form, moves)
    tiny = math.radians(1e-3)  # first order holds
    run = simulate(p, 3000, tiny, seed=11)
    for k in (len(p.steps) // 2, len(p.steps)):
        err = (run.estimates[:, k] - run.truth[k]).reshape(len(run.estimates), 6)
        sample = np.cov(err.T)
        cov = predict(p, tiny)[k]
        assert np.linalg.norm(sample - cov) < 0.08 * np.linalg.norm(cov), (form, moves, k)
    # and at the paper's noise the RMS at the goal
    full = simulate(p, 3000, seed=12)
    d = full.estimates[:, -1, p.steps[-1].robot] - p.steps[-1].target
    assert predicted_goal_rms(p) == pytest.approx(np.sqrt((d**2).sum(1).mean()), rel=0.05)


def test_prediction_stays_positive_semidefinite_on_long_chains() -> None:
    p = plan(1, 71, None, START, (0.0, 21.5))
    for cov in predict(p):
        assert np.linalg.eigvalsh(cov).min() >= -1e-12 * max(1.0, np.trace(cov))


def test_planner_beats_every_swept_setting() -> None:
    chosen = plan_moves()
    assert np.allclose(chosen.steps[-1].target, GOAL)
    for m in chosen.steps:
        assert m.robot not in m.standing and len(set(m.standing)) == 2
        assert np.abs(m.target[0] - GOAL[0]) <= 2.0 + 1e-9  # within its region
    swept = [plan(1, n) for n in range(1, 40, 2)] + [plan(2, n) for n in range(1, 31)]
    best = min(swept, key=predicted_goal_rms)
    assert predicted_goal_rms(chosen) < 0.9 * predicted_goal_rms(best)
    ours = simulate(chosen, 3000, seed=21).goal_errors.mean()
    theirs = simulate(best, 3000, seed=21).goal_errors.mean()
    assert ours < theirs
    with pytest.raises(ValueError, match="spacing"):
        plan_moves(spacing=0.0)


# --- the 3-D case ---

from kiseki.coop import simulate_3d  # noqa: E402


def _wavy(x, y):
    return 0.5 * np.sin(2 * np.pi * x / 4.0) * np.cos(2 * np.pi * y / 4.0)


def test_three_d_on_uneven_ground() -> None:
    p = plan(2, 7)
    exact = simulate_3d(p, _wavy, 5, angle_sigma=0.0, elevation_sigma=0.0)
    assert exact.goal_errors.max() < 1e-9
    assert exact.truth[-1, p.steps[-1].robot, 2] == pytest.approx(_wavy(0.0, 10.0) + 0.5)
    # flat ground: the horizontal error is the planar one (elevations add range information)
    flat = simulate_3d(p, lambda x, y: np.zeros_like(x), 3000, seed=3)
    planar = simulate(p, 3000, seed=3).goal_errors.mean()
    horizontal = np.hypot(*flat.goal_offsets[:, :2].T).mean()
    assert 0.75 * planar < horizontal <= 1.05 * planar
    wavy = simulate_3d(p, _wavy, 3000, seed=3)
    assert np.abs(wavy.goal_offsets[:, 2]).mean() < 0.2 * horizontal  # height from elevations
    with pytest.raises(ValueError, match="ground"):
        simulate_3d(p, lambda x, y: np.zeros(3))
    with pytest.raises(ValueError, match="marker_height"):
        simulate_3d(p, _wavy, marker_height=-1.0)


# --- the turns in the simulator ---


def test_the_scene_takes_the_turns_of_form_2_and_its_bearings_triangulate(tmp_path) -> None:
    from kiseki.io.runlog import read_run
    from kiseki.sim.run import SimConfig
    from kiseki.sim.run import simulate as run_scene
    from kiseki.sim.scene import load_scene

    root = __import__("pathlib").Path(__file__).resolve().parents[3]
    scene = load_scene(root / "data" / "worlds" / "coop_three_robots.yaml")
    names = ["r1", "r2", "r3"]
    # the scene says what it is: kiseki.coop.plan(2, 7) from the paper's start, goal (0, 10)
    p = plan(2, 7)
    starts = np.array([spec["robot"]["start"][:2] for spec in scene.robot_specs], dtype=float)
    np.testing.assert_allclose(starts, START)
    assert scene.turns["goal"] == (0.0, 10.0)
    assert [m for m, _ in scene.turns["moves"]] == [names[s.robot] for s in p.steps]
    np.testing.assert_allclose([to for _, to in scene.turns["moves"]], [s.target for s in p.steps],
                               atol=1e-4)  # fmt: skip
    # the paper's robots are points (the scene's point_robots): the plan drives the 0.70 m
    # bodies through each other, and they do not collide
    config = SimConfig(seed=3)
    summary = run_scene(scene, tmp_path / "coop.mcap", config, progress=False)
    assert summary.reached_goal
    run = read_run(tmp_path / "coop.mcap")

    def track(name: str) -> np.ndarray:
        return np.array(
            [
                [m["pose"]["position"]["x"], m["pose"]["position"]["y"]]
                for _, m in run.messages(f"/{name}/ground_truth")
            ]
        )

    truth = {n: track(n) for n in names}
    times = np.array([t for t, _ in run.messages("/r1/ground_truth")])
    bearings = {n: run.messages(f"/{n}/bearings") for n in names}
    events = run.messages("/turns")
    assert [e["event"] for _, e in events] == ["start", "arrived"] * 7
    errors = []
    for (t0, start), (t1, arrived) in zip(events[0::2], events[1::2], strict=True):
        k0, k1 = int(np.searchsorted(times, t0)), int(np.searchsorted(times, t1))
        mover = arrived["robot"]
        for n in names:  # one robot drives at a time
            moved = np.linalg.norm(truth[n][k1] - truth[n][k0])
            assert (moved > 1.0) if n == mover else (moved < 1e-9), (start, n)
        assert np.linalg.norm(truth[mover][k1] - arrived["to"]) < 0.15
        # the standing robots' logged bearings, turned into the paper's angles, triangulate it
        i, j = [n for n in names if n != mover]
        world = []
        for a, b in ((i, j), (j, i)):
            msg = bearings[a][k1][1]
            rel = dict(zip(msg["targets"], msg["bearings"], strict=True))
            angle = rel[mover] - rel[b]  # between the other standing robot and the mover
            base = truth[b][k1] - truth[a][k1]
            world.append(math.atan2(base[1], base[0]) + angle)
        found = triangulate(np.stack([truth[i][k1], truth[j][k1]]), world)
        errors.append(np.linalg.norm(found - truth[mover][k1]))
    assert max(errors) < 0.05 and len(errors) == 7  # 0.1 deg over a few metres: millimetres


def test_the_papers_analytic_optimum_n_equals_tan_theta_e() -> None:
    from kiseki_experiments.coop.coop_optimum import analytic_optimum

    n, theta, _ = analytic_optimum(10.0, 1.0)
    assert (n, round(theta, 6)) == (10, 45.0)  # eqs. 5-6 for the paper's goal
    assert analytic_optimum(6.0, 1.0)[0] == 6  # n = tan(theta_e) = L / d elsewhere too
    assert analytic_optimum(10.0, 2.0)[0] == 5


@pytest.mark.parametrize("deg", [40.0, 55.0, 70.0])
def test_form1_readings_meet_at_their_closed_form_sight_angles(deg) -> None:
    """Past the first unit (which keeps the start's width), pair and scout sees its joiner
    along lines meeting at atan(tan(theta) / 3), crossing at theta itself; the scouts' apexes
    at pi - 2 theta in both; both readings reach the goal in the same moves."""
    theta = math.radians(deg)
    scout_pair, crossing = (plan(1, 15, theta, reading=r) for r in ("pair-scout", "crossing"))
    for p, joiner in ((scout_pair, math.atan(math.tan(theta) / 3)), (crossing, theta)):
        a = p.sight_angles()
        np.testing.assert_allclose(a[3:13:2], joiner, atol=1e-9)  # the joiners of units 2-7
        np.testing.assert_allclose(a[2:13:2], min(math.pi - 2 * theta, 2 * theta), atol=1e-9)
        np.testing.assert_allclose(p.steps[-1].target, GOAL)
    with pytest.raises(ValueError, match="reading must be one of"):
        plan(1, 15, theta, reading="diagonal")


def test_per_repeat_argmin_against_brute_force() -> None:
    import pandas as pd

    from kiseki_experiments.coop.coop_claims import _per_repeat_argmin, _per_repeat_min

    rng = np.random.default_rng(3)
    values = rng.uniform(0.01, 0.1, (6, 5))  # 6 settings, 5 repeats
    rows = pd.DataFrame({"moves": [1, 3, 5, 7, 9, 11], "repeat_mean_m": list(values)})
    want = [rows["moves"][int(np.argmin(values[:, r]))] for r in range(5)]
    assert _per_repeat_argmin(rows, "moves", "repeat_mean_m").tolist() == want
    assert _per_repeat_min(rows).tolist() == values.min(axis=0).tolist()
