# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""coop-forms: the simulation study of Hirose, Nagata and Kurazume (sec. 4, Figs. 5-8).

Three robots start at (-1, 0), (1, 0) and (0, -1) and advance to the goal (0, 10) by taking
turns (kiseki.coop.positioning, which defines the two movement forms); every measured angle has
Gaussian noise of SD 0.1 deg; 100 runs per setting; the error is the distance between the goal
and the estimate of the robot that moved there. Figs. 5-6 (versus moves): as in the paper's
simulation, the formation keeps the start's width, so the number of moves sets the
representative angle. Figs. 7-8 (versus the representative angle) have a sweep of their own:
the angle varied at a fixed number of moves per form (``angle_moves``), the formation's width
following from it. Form 1 is run in each of kiseki's readings (``form1_readings``,
kiseki.coop.positioning: pair and scout, and crossing). Trial i is one setting; the last
trials are the anchors:
dead reckoning over the same distance with the simulator's omnidirectional odometry model, and
kiseki's scheme over the 21.5 m that Kurazume and Hirose's CPS-II reported (0.12 % error),
the move planner, and the 3-D case on uneven ground for the best setting of each form.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

import numpy as np
import pandas as pd

from kiseki.coop import GOAL, START, paper_angle, plan, simulate, simulate_3d
from kiseki.coop.planner import plan_moves, predicted_goal_rms
from kiseki.coop.positioning import FORM1_READINGS
from kiseki.core import derive_seed
from kiseki.plots import new_figure
from kiseki.sim.motion import BodyMotion
from kiseki.sim.odometry import OmniOdometry
from kiseki_experiments.coop.coop_claims import (
    CPS2_DISTANCE,
    N_PAPER,
    claim_evidence,
    claims,
)
from kiseki_experiments.coop.coop_optimum import analytic_optimum
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    Count,
    NonEmpty,
    NonNegativeReal,
    PositiveReal,
    Real,
    Runs,
    Spacing,
)


@dataclass(frozen=True)
class CoopFormsConfig:
    runs: Runs = 100  # per setting (the paper's)
    angle_sigma_deg: NonNegativeReal = 0.1  # the paper's
    # the 3-D case's elevation angles: as noisy as the horizontal ones (the paper gives none)
    elevation_sigma_deg: NonNegativeReal = 0.1
    form1_moves: Annotated[list[Count], NonEmpty] = field(
        default_factory=lambda: list(range(1, 40, 2))
    )
    form2_moves: list[Count] = field(default_factory=lambda: list(range(1, 31)))
    form1_readings: list[str] = field(default_factory=lambda: list(FORM1_READINGS))
    # Figs. 7-8: the representative angle swept at a fixed number of moves per form (form 1,
    # form 2): the middles of the paper's best ranges (10-20 and 5-10 moves); from 30 deg, as
    # below it form 2's second move (from the start's width to the formation's) has lines of
    # sight that nearly meet head on (0.01 deg at 25 deg, 7 moves) and cannot be triangulated
    angles_deg: Annotated[list[Real], NonEmpty] = field(
        default_factory=lambda: [float(a) for a in range(30, 85, 5)]
    )
    angle_moves: list[Count] = field(default_factory=lambda: [15, 7])
    # each sweep setting is simulated this many times (runs each, seeds derived from the
    # trial's): the claims' intervals are over these repeats of the whole sweep
    repeats: Count = 10
    anchors: bool = True  # dead reckoning, CPS-II, the planner, 3-D (the controls drop them)
    dead_reckoning_runs: Runs = 1000  # split among the repeats
    planner_max_moves: Count = 60  # kiseki.coop.planner.plan_moves' limit (1: straight there)
    step: Spacing = 0.05  # m, dead reckoning's odometry step
    # the 3-D case: uneven ground z = A sin(2 pi x / L) cos(2 pi y / L), markers 0.5 m above it
    ground_amplitude: NonNegativeReal = 0.5  # m
    ground_wavelength: PositiveReal = 4.0  # m


def _settings(config: CoopFormsConfig) -> list[tuple]:
    """(kind, form, moves, angle in deg or None, form 1's reading or "") of every trial."""
    r1 = config.form1_readings
    rows = [("sweep", 1, n, None, r) for r in r1 for n in config.form1_moves]
    rows += [("sweep", 2, n, None, "") for n in config.form2_moves]
    if len(config.angle_moves) != 2:  # the trial count is taken from here before preflight
        raise ValueError("coop-forms: angle_moves takes 2 counts (form 1, form 2)")
    m1, m2 = config.angle_moves
    rows += [("angle", 1, m1, a, r) for r in r1 for a in config.angles_deg]
    rows += [("angle", 2, m2, a, "") for a in config.angles_deg]
    if not config.anchors:
        return rows
    anchors = [("dead-reckoning", 0, 0, None, ""), ("cps2", 1, 0, None, r1[0]),
               ("cps2", 2, 0, None, ""), ("planner", 0, 0, None, "")]  # fmt: skip
    return rows + anchors + [("3d", 1, 5, None, r1[0]), ("3d", 2, 7, None, "")]


def preflight(config: CoopFormsConfig) -> None:
    if config.runs < 2 or config.dead_reckoning_runs < 2 * config.repeats:
        raise ValueError("coop-forms: runs must be >= 2 and dead_reckoning_runs >= 2 x repeats")
    for name in ("angle_sigma_deg", "elevation_sigma_deg"):
        if not 0 < getattr(config, name) < 10:
            raise ValueError(f"coop-forms: {name} must lie in (0, 10)")
    bad = [r for r in config.form1_readings if r not in FORM1_READINGS]
    if not config.form1_readings or bad:
        raise ValueError(f"coop-forms: form1_readings must be some of {', '.join(FORM1_READINGS)}")
    settings = _settings(config)  # refuses angle_moves without 2 counts
    for n in (*config.form1_moves, config.angle_moves[0]):
        if n < 1 or n % 2 == 0:
            raise ValueError(f"coop-forms: form 1 takes odd move counts, got {n}")
    for kind, form, moves, angle, reading in settings:
        if kind in ("sweep", "angle"):  # raises for a count or angle out of range
            plan(form, moves, None if angle is None else math.radians(angle), reading=reading or
                 FORM1_READINGS[0])  # fmt: skip


def _errors(
    form, moves, angle, reading, goal, runs: int, sigma: float, seed: int, repeats: int = 1
) -> dict:
    """One setting's errors at the goal: the first repeat's runs in full, and per repeat (each
    ``runs`` runs on a seed derived from ``seed``) the mean error and the along-track RMS."""
    the_plan = plan(form, moves, None if angle is None else math.radians(angle), START, goal,
                    reading or FORM1_READINGS[0])  # fmt: skip
    run = simulate(the_plan, runs, sigma, seed)
    again = [simulate(the_plan, runs, sigma, derive_seed(seed, r)) for r in range(1, repeats)]
    ends = [run, *again]
    last = the_plan.steps[-1]
    offsets = [r.estimates[:, -1, last.robot] - last.target for r in ends]
    last = run.plan.steps[-1]
    d = run.estimates[:, -1, last.robot] - last.target
    e = np.hypot(d[:, 0], d[:, 1])
    return {
        "form": form,
        "reading": reading,
        "moves": moves,
        "angle_deg": math.degrees(run.plan.angle),
        "mean_error_m": float(e.mean()),
        "sd_error_m": float(e.std(ddof=1)),
        "rms_error_m": float(np.sqrt(np.mean(e**2))),
        "along_rms_m": float(np.sqrt(np.mean(d[:, 1] ** 2))),
        "cross_rms_m": float(np.sqrt(np.mean(d[:, 0] ** 2))),
        "predicted_rms_m": predicted_goal_rms(run.plan, sigma),
        "min_sight_angle_deg": float(np.degrees(the_plan.sight_angles().min())),
        "errors_m": [round(float(v), 7) for v in e],
        "along_m": [round(float(v), 7) for v in d[:, 1]],
        "repeat_mean_m": [float(np.hypot(o[:, 0], o[:, 1]).mean()) for o in offsets],
        "repeat_along_rms_m": [float(np.sqrt(np.mean(o[:, 1] ** 2))) for o in offsets],
    }


def _dead_reckoning(config: CoopFormsConfig, seed: int) -> dict:
    """The scout's straight drive from (0, -1) to the goal on odometry alone; the runs split
    into ``repeats`` groups, each group's mean error one repeat's."""
    distance = float(np.hypot(*(GOAL - START[2])))
    steps = int(math.ceil(distance / config.step))
    step = distance / steps
    heading = math.atan2(*(GOAL - START[2])[::-1])
    errors = np.empty(config.dead_reckoning_runs)
    for r in range(config.dead_reckoning_runs):
        odo = OmniOdometry(seed=(seed + r) % 2**64, initial_pose=(*START[2], heading))
        for _ in range(steps):
            odo.update(BodyMotion(step, 0.0, 0.0, step, 0.1))
        p = odo.pose
        errors[r] = math.hypot(p.x - GOAL[0], p.y - GOAL[1])
    groups = np.array_split(errors, config.repeats)
    return {"distance_m": distance, "mean_error_m": float(errors.mean()), "steps": steps,
            "repeat_mean_m": [float(g.mean()) for g in groups]}  # fmt: skip


def trial(config: CoopFormsConfig, index: int, seed: int) -> TrialOutput:
    settings = _settings(config)
    if index >= len(settings):
        raise ValueError(f"coop-forms: {len(settings)} trials (settings), index {index}")
    kind, form, moves, angle, reading = settings[index]
    sigma = math.radians(config.angle_sigma_deg)
    if kind in ("sweep", "angle"):
        row = _errors(form, moves, angle, reading, GOAL, config.runs, sigma, seed, config.repeats)
        return TrialOutput({"kind": kind, **row})
    if kind == "dead-reckoning":
        return TrialOutput({"kind": kind, "form": 0, "moves": 0, **_dead_reckoning(config, seed)})
    if kind == "3d":
        a, wl = config.ground_amplitude, config.ground_wavelength

        def ground(x, y):
            return a * np.sin(2 * np.pi * x / wl) * np.cos(2 * np.pi * y / wl)

        the_plan = plan(form, moves, reading=reading or FORM1_READINGS[0])
        e_sigma = math.radians(config.elevation_sigma_deg)
        across, height, planar = [], [], []
        for r in range(config.repeats):  # repeat 0 on the trial's seed, as the sweeps
            rs = seed if r == 0 else derive_seed(seed, r)
            off = simulate_3d(the_plan, ground, config.runs, sigma, e_sigma, seed=rs).goal_offsets
            across.append(float(np.hypot(off[:, 0], off[:, 1]).mean()))
            height.append(float(np.abs(off[:, 2]).mean()))
            planar.append(float(simulate(the_plan, config.runs, sigma, rs).goal_errors.mean()))
        return TrialOutput(
            {
                "kind": kind,
                "form": form,
                "moves": moves,
                "horizontal_m": float(np.mean(across)),
                "vertical_m": float(np.mean(height)),
                "planar_m": float(np.mean(planar)),
                "repeat_horizontal_m": across,
                "repeat_planar_m": planar,
            }
        )
    if kind == "planner":
        chosen = plan_moves(START, GOAL, sigma, max_moves=config.planner_max_moves)
        ends = [simulate(chosen, config.runs, sigma, seed if r == 0 else derive_seed(seed, r))
                for r in range(config.repeats)]  # fmt: skip
        run = ends[0]
        return TrialOutput(
            {
                "kind": kind,
                "form": 0,
                "moves": chosen.moves,
                "mean_error_m": float(run.goal_errors.mean()),
                "sd_error_m": float(run.goal_errors.std(ddof=1)),
                "predicted_rms_m": predicted_goal_rms(chosen, sigma),
                "repeat_mean_m": [float(e.goal_errors.mean()) for e in ends],
                "targets": [[round(float(v), 3) for v in m.target] for m in chosen.steps],
                "movers": [m.robot + 1 for m in chosen.steps],
            }
        )
    # CPS-II's distance, with the start's width: of every move count whose angle is in range,
    # the one with the smallest predicted error (first order, kiseki.coop.planner: no sampling,
    # so the repeats that judge it did not choose it)
    goal = np.array([0.0, CPS2_DISTANCE])
    best = None
    for n in range(1, 81):
        if form == 1 and n % 2 == 0:
            continue
        if not math.radians(5) <= paper_angle(form, n, START, goal) <= math.radians(85):
            continue
        rms = predicted_goal_rms(plan(form, n, None, START, goal, reading or FORM1_READINGS[0]),
                                 sigma)  # fmt: skip
        if best is None or rms < best[0]:
            best = (rms, n)
    row = _errors(form, best[1], None, reading, goal, config.runs, sigma, seed, config.repeats)
    return TrialOutput({"kind": kind, **row, "distance_m": CPS2_DISTANCE})


COLUMNS = ["form", "reading", "moves", "angle_deg", "mean_error_m", "sd_error_m", "along_rms_m",
           "cross_rms_m", "predicted_rms_m", "min_sight_angle_deg"]  # fmt: skip


def _groups(ok: pd.DataFrame, kind: str, key: str) -> dict[str, pd.DataFrame]:
    """The rows of one sweep by form and form 1's reading, sorted by ``key``."""
    rows = ok[ok["kind"] == kind]
    out = {}
    for (form, reading), g in rows.groupby(["form", "reading"], sort=True):
        label = f"form 1 ({reading})" if int(form) == 1 else "form 2"
        out[label] = g.sort_values(key)
    return out


def analyze(config: CoopFormsConfig, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path):
    ok = trials[trials["error"].isna()]
    forms = _groups(ok, "sweep", "moves")
    angles = _groups(ok, "angle", "angle_deg")
    sweep = pd.concat(forms.values()) if forms else ok.iloc[:0]
    table = sweep[COLUMNS].reset_index(drop=True) if forms else pd.DataFrame(columns=COLUMNS)
    figure_paths: list[Path] = []

    def spread(rows: pd.DataFrame) -> float:
        band = rows[(rows["angle_deg"] >= 30) & (rows["angle_deg"] <= 75)]
        return float(band["mean_error_m"].max() / band["mean_error_m"].min())

    distance = float(GOAL[1] - START[:2, 1].mean())
    n_opt, theta_opt, _ = analytic_optimum(distance)
    extra = {
        "paper_algebra": pd.DataFrame(
            [
                {
                    "n": n_opt,
                    "theta_deg": theta_opt,
                    "n_tan_theta_e": N_PAPER,
                    "source": "eq. 4 summed over n steps, brute force over n (the paper's algebra)",
                }
            ]
        )  # fmt: skip
    }
    if angles:
        extra["angle_sweep"] = pd.concat(angles.values())[COLUMNS].reset_index(drop=True)
        # Figs. 7-8's flatness: a table row (no control can make the comparison fail for sure)
        extra["angle_spread"] = pd.DataFrame(
            [{"sweep": k, "max_over_min_30_75_deg": spread(r)} for k, r in angles.items()]
        )
    dead = ok[ok["kind"] == "dead-reckoning"]
    anchors = ok[ok["kind"] == "cps2"]
    if len(dead):
        extra["dead_reckoning"] = pd.DataFrame([dead.iloc[0][["distance_m", "mean_error_m"]]])
    planned = ok[ok["kind"] == "planner"]
    if len(planned):
        extra["planner"] = pd.DataFrame(
            [planned.iloc[0][["moves", "mean_error_m", "sd_error_m", "predicted_rms_m"]]]
        )
    three = ok[ok["kind"] == "3d"]
    if len(three):
        rows = three[["form", "moves", "horizontal_m", "vertical_m", "planar_m"]]
        extra["three_d"] = rows.reset_index(drop=True)
    if len(anchors):
        rows = anchors[["form", "reading", "moves", "angle_deg", "mean_error_m", "distance_m"]]
        rows = rows.assign(error_percent=100 * rows["mean_error_m"] / rows["distance_m"])
        extra["cps2_anchor"] = rows.reset_index(drop=True)
    if forms or angles:
        fig = new_figure(figsize=(10, 7), dpi=120)
        axes = fig.subplots(2, 2)
        for row, (groups, x, label) in enumerate(
            ((forms, "moves", "number of moves"), (angles, "angle_deg", "angle (deg)"))
        ):
            for name, rows in groups.items():
                f = int(rows["form"].iloc[0])
                ax = axes[row, f - 1]
                ax.errorbar(rows[x], 1000 * rows["mean_error_m"], 1000 * rows["sd_error_m"],
                            fmt="o-", ms=3, capsize=2, label=name)  # fmt: skip
                ax.set_xlabel(label)
                ax.set_ylabel("error at the goal (mm)")
                ax.set_title(f"form {f}: Fig. {4 + f + 2 * row}", fontsize=9)
                ax.legend(fontsize=7)
        fig.tight_layout()
        path = figures / "coop_forms.png"
        fig.savefig(path)
        figure_paths.append(path)
    notes = (
        f"{config.runs} runs per setting, angle noise {config.angle_sigma_deg} deg; mean and SD "
        "of the distance between the goal and the estimate of the robot that moved there. The "
        "movement forms are kiseki's readings (kiseki.coop.positioning): the paper's drawings "
        "are not in its text. Form 1 (pair and scout) sees its joiner along lines of sight "
        "meeting at atan(tan(theta) / 3) (25 deg at 55 deg); form 1 (crossing) moves the other "
        "pair robot so that they meet at theta (min_sight_angle_deg in the tables). Figs. 5-6 "
        "keep the start's width (the angle follows from the moves); Figs. 7-8 sweep the angle "
        f"at {config.angle_moves[0]} (form 1) and {config.angle_moves[1]} (form 2) moves. "
        "paper_algebra is the paper's sec. 3.1 minimised as printed (a table row: it cannot "
        "fail); the claims on n = tan(theta_e) compare the simulation's optimum with it. "
        f"The anchors are repeated {config.repeats} times as the sweeps (dead reckoning's "
        f"{config.dead_reckoning_runs} runs split among the repeats); CPS-II's move count per "
        "form is the one with the smallest predicted error (first order, no sampling); the "
        f"3-D case has elevation angles {config.elevation_sigma_deg} deg noisy."
    )
    return Analysis(
        tables={"sweep": table, **extra}, figures=figure_paths, notes=notes,
        evidence=claim_evidence(forms, angles, ok),
    )  # fmt: skip


def setting_count(config: CoopFormsConfig) -> int:
    return len(_settings(config))


EXPERIMENT = Experiment(
    name="coop-forms",
    paper="001 cooperative positioning (Hirose, Nagata, Kurazume)",
    artefact="Figs. 5-8: error at the goal vs moves and representative angle, forms 1 and 2",
    description="cooperative positioning of three robots: the two movement forms swept",
    config_type=CoopFormsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=len(_settings(CoopFormsConfig())),
    preflight=preflight,
    trial_count=setting_count,
    claims=claims(CoopFormsConfig, setting_count),
)
