# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki localize``: localization along a recorded log (position tracking, or global)."""

from __future__ import annotations

import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import typer
import yaml
from rich.console import Console

from kiseki._support.atomic import atomic_write
from kiseki._support.guard import Derived, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import (
    BEAM_LIMIT,
    PARTICLE_LIMIT,
    THREAD_LIMIT,
    Count,
    Fraction,
    Quantity,
    Seed,
)
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki._support.table import show_fields
from kiseki.cli._defaults import default_of
from kiseki.cli._localize_checks import refuse_unused_by_localize
from kiseki.cli._off_map import warn_if_off_the_map
from kiseki.datasets import open_scans
from kiseki.filters import (
    CostModel,
    GlobalConfig,
    LocalizeConfig,
    describe,
    global_localize,
    localize,
    render_global,
    write_report,
)
from kiseki.grid import RAY_CASTERS
from kiseki.io.ros_map import load_map
from kiseki.metrics import ape

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)
# files the command writes that no option names (kiseki._support.guard)
_CONFIG_BESIDE = Derived(
    "its config", lambda a: a["output"].with_name(a["output"].stem + ".config.yaml")
)
_COST_MODEL = Derived(  # the cost model a budget calibrated (one given is not rewritten)
    "its cost model",
    lambda a: (
        _cost_path(a["output"])
        if a.get("budget_ms") is not None and a.get("cost_model") is None
        else None
    ),
)
_GLOBAL_REPORT = Derived(
    "its report", lambda a: a["output"].with_suffix(".json") if a["global_start"] is True else None
)


@app.command("localize")
@guarded(
    inputs=("log", "map_file", "cost_model"),
    outputs=("output", _CONFIG_BESIDE, _GLOBAL_REPORT, _COST_MODEL, "plot"),
)
@interruptible()
def localize_command(
    ctx: typer.Context,
    log: Path = typer.Argument(
        ...,
        help="CARMEN log (.log, .log.gz), kiseki run (.mcap), CMU Wean robotdata log, ROS 1 bag "
        "(.bag) or ROS 2 bag (folder, .db3 or .mcap).",
    ),
    map_file: Path = typer.Option(
        ..., "--map", help="ROS map YAML of the log's building, or a CMU .dat(.gz) map."
    ),
    # LocalizeConfig's method, GlobalConfig's too (the same: a test holds them equal)
    method: str = typer.Option(
        default_of(LocalizeConfig, "method"),
        help="beam, likelihood-field, space-observation (the thesis'), ray-space-observation "
        "(kiseki's: the thesis' penetration per ray, and where beams end) or odometry.",
    ),
    seed: int = typer.Option(
        default_of(LocalizeConfig, "seed"),
        parser=Seed(),
        help="Seed of the filter and of the odometry noise.",
    ),
    # the defaults are the configs' (LocalizeConfig; GlobalConfig with --global), shown here
    # an SD up to the step itself: beyond it the odometry says nothing of the motion
    odometry_noise: float | None = typer.Option(
        None,
        parser=Fraction("--odometry-noise", 0, 1),
        help="Odometry noise SD, fraction of each step (default "
        f"{LocalizeConfig.odometry_noise:g}); not with --global.",
    ),
    particles: int | None = typer.Option(
        None,
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help=f"Particles (default {LocalizeConfig.particles:,}; {GlobalConfig.particles:,} at the "
        "start with --global); with --kld the maximum.",
    ),
    kld: bool = typer.Option(False, "--kld", help="Adapt the particle count by KLD sampling."),
    beams: int | None = typer.Option(
        None,
        parser=Count("--beams", 0, BEAM_LIMIT, "0 = every beam"),
        help=f"Beams used per scan, nav2's max_beams (default {LocalizeConfig.beams}; "
        f"{GlobalConfig.beams} with --global); not with space-observation.",
    ),
    recovery: str | None = typer.Option(
        None,
        help="none, augmented (Augmented MCL) or resetting (expansion, then sensor resetting); "
        f"with --global from the cloud's convergence on (default {LocalizeConfig.recovery}).",
    ),
    reset_proposal: str | None = typer.Option(
        None,
        help="With --recovery resetting: the sensor reset's candidates, uniform over the free "
        "cells or around the correlative scan matcher's best poses for the scan (matcher); "
        f"default {LocalizeConfig.sensor_reset_proposal}; not with --global.",
    ),
    search_every: int | None = typer.Option(
        None,
        "--matcher-search-every",
        parser=Count("--matcher-search-every", 1, 1000),
        help="With --reset-proposal matcher: a lost filter searches the map on every N-th "
        f"sensor reset only (1: on every one; default {LocalizeConfig.matcher_search_every}).",
    ),
    reset_look_elsewhere: bool = typer.Option(
        False,
        "--reset-look-elsewhere",
        help="A sensor reset must beat the cloud by a margin that grows by ln N for its best of "
        "N poses searched (N the candidates, or the matcher's lattice poses); not with --global.",
    ),
    reset_unchecked: bool = typer.Option(
        False,
        "--reset-unchecked",
        help="Resets are kept on the likelihood alone, without the map's agreement at the place "
        "they propose, and a sensor reset is made at once, without the next scan's "
        "confirmation (kiseki's resets before both checks); not with --global.",
    ),
    intrusion_tolerant: bool = typer.Option(
        False,
        "--intrusion-tolerant-resets",
        help="With --method ray-space-observation --recovery resetting: the cloud counts as "
        "lost only where beams pass through walls, not where they end short in the open "
        "(unmapped people, carts), and the likelihood-drop trigger is off; not with --global.",
    ),
    threads: int | None = typer.Option(
        None,
        parser=Count("--threads", 0, THREAD_LIMIT, "0 = chosen by measured time"),
        help=f"Threads (0: all cores, or one while it is faster; default {LocalizeConfig.threads})",
    ),
    reliability_estimate: str | None = typer.Option(
        None,
        "--reliability",
        help="The CSV's reliability: agreement (the engine's recent share of scans that agree "
        "with the map), learned (a probability of being within 1 m and 10 deg, fitted on "
        "simulated updates) or learned-real (the same, fitted on recorded laser logs); "
        f"default {LocalizeConfig.reliability}; not with --global.",
    ),
    budget_ms: float | None = typer.Option(
        None,
        parser=Quantity("--budget-ms", 0, 1e6, "ms", lo_open=True),
        help="Time budget per update: the particle count (with --kld its maximum) and the beams "
        "are chosen from a cost model so that the predicted update time fits it (tracking, "
        "likelihood-field and beam); the choice is printed and saved with the config.",
    ),
    cost_model: Path | None = typer.Option(
        None,
        help="With --budget-ms: the cost model (JSON) of an earlier run, so that a rerun with the "
        "same seed gives the same output; without it the model is calibrated on this log and "
        "written beside the output as OUTPUT-STEM.cost.json.",
    ),
    caster: str | None = typer.Option(
        None,
        help=f"Beam model: how the expected ranges z* are cast ({', '.join(RAY_CASTERS)}; "
        f"both exact, the same weights); default {LocalizeConfig.caster}.",
    ),
    beam_skip: bool = typer.Option(
        False,
        "--beam-skip",
        help="Likelihood field: nav2's beam skipping (weigh only beams that end near a wall for "
        "enough particles).",
    ),
    global_start: bool = typer.Option(
        False,
        "--global",
        help="Global localization: start uniformly over the map's free cells (no initial pose).",
    ),
    one_scan: bool = typer.Option(
        False,
        "--one-scan",
        help="With --global: start around the first scan's best poses over the whole map "
        "(one-scan relocalization) instead of uniformly.",
    ),
    tracking_particles: int | None = typer.Option(
        None,
        parser=Count("--tracking-particles", 1, PARTICLE_LIMIT),
        help="With --global: particles kept once the cloud has converged (default "
        f"{GlobalConfig.tracking_particles:,}).",
    ),
    tracking_method: str | None = typer.Option(
        None,
        help="With --global: the model once the cloud has converged (likelihood-field, "
        "space-observation or ray-space-observation), e.g. the field to find the place and "
        "kiseki's ray model to track it among unmapped objects; default: --method.",
    ),
    plot: Path | None = typer.Option(
        None, help="With --global: draw the map, the estimates and where they converged (PNG)."
    ),
    output: Path = typer.Option(
        ..., "-o", "--output", help="CSV t,x,y,theta,reliability to write."
    ),
    scan_topic: str = typer.Option("/scan", help="ROS bags: the sensor_msgs/LaserScan topic."),
    odom_topic: str = typer.Option(
        "/odom", help="ROS bags: the nav_msgs/Odometry topic (if absent: odom -> base on /tf)."
    ),
    reference_topic: str | None = typer.Option(
        None, help="ROS bags: a nav_msgs/Odometry topic of reference poses, e.g. /ground_truth."
    ),
    as_json: bool = typer.Option(
        False, "--json", help="Print the errors (and the convergence report) as one JSON object."
    ),
) -> None:
    """Localize along a log: position tracking from its first reference pose, or with --global
    from a uniform start. Prints the absolute pose error against the log's reference poses when
    it has them; with --global also the convergence report (written to OUTPUT.json too); with
    --json the same numbers as one JSON object. The settings it ran with are written beside the
    output as OUTPUT-STEM.config.yaml.

    Example: kiseki localize run.mcap --map data/maps/factory_corridor.yaml -o track.csv --json"""
    refuse_unused_by_localize(ctx, method, global_start, recovery, reset_proposal)
    if cost_model is not None and budget_ms is None:
        raise ValueError("--cost-model applies only with --budget-ms")

    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    if not global_start:
        for name, value in (
            ("--tracking-particles", tracking_particles),
            ("--tracking-method", tracking_method),
            ("--plot", plot),
        ):
            if value is not None:
                raise ValueError(f"{name} applies only with --global")
        if one_scan:
            raise ValueError("--one-scan applies only with --global")
    elif reliability_estimate is not None:
        raise ValueError("--reliability applies only to tracking (not with --global)")
    if global_start and output.suffix.lower() == ".json":
        raise ValueError(f"{output}: the report goes to OUTPUT.json: give a .csv output")
    scans = open_scans(
        log, scan_topic=scan_topic, odom_topic=odom_topic, reference_topic=reference_topic
    )
    grid = load_map(map_file)
    reliability = np.full(len(scans), np.nan)
    shared = dict(method=method, seed=seed, particles=particles, kld=kld, beams=beams)
    shared.update(recovery=recovery, threads=threads)
    if global_start:
        start = "one-scan" if one_scan else None  # else GlobalConfig's default
        gconfig = GlobalConfig(
            **_given(
                **shared,
                tracking_particles=tracking_particles,
                start=start,
                tracking_method=tracking_method,
            )
        )
        saved_config = {"command": "localize --global", **asdict(gconfig)}
        result = global_localize(scans, grid, gconfig, progress=True)
        trajectory, reliability = result.estimates, result.reliability
    else:
        resets = dict(sensor_reset_proposal=reset_proposal, matcher_search_every=search_every)
        resets.update(reset_look_elsewhere=reset_look_elsewhere or None)  # None: the default
        resets.update(intrusion_tolerant_resets=intrusion_tolerant or None)
        if reset_unchecked:
            resets.update(reset_needs_agreement=False, sensor_reset_confirm=False)
        budget = dict(budget_ms=budget_ms, beam_skip=beam_skip or None, caster=caster)
        config = LocalizeConfig(
            **_given(
                **shared, odometry_noise=odometry_noise, reliability=reliability_estimate, **budget
            ),
            **_given(**resets),
        )
        cost = CostModel.load(cost_model) if cost_model is not None else None
        if not scans.has_reference_poses:
            raise ValueError(f"{log}: the log has no reference poses to start from: use --global")
        saved_config = {"command": "localize", **config.to_dict()}
        tracked = localize(scans, grid, config, progress=True, cost_model=cost)
        trajectory, reliability = tracked.estimates, tracked.reliability
        if tracked.budget is not None:
            saved_config.update(budget=asdict(tracked.budget))
            saved_config.update(cost_model=tracked.cost_model.to_dict())
    saved_config.update(log=str(log), map=str(map_file))
    _write_trajectory(output, scans.times, trajectory, reliability)
    if not global_start:
        warn_if_off_the_map(grid, trajectory, scans, map_file)
    elif result.report.converged and result.report.fit is not None:  # from convergence on
        warn_if_off_the_map(grid, trajectory, scans, map_file, result.report.fit.within_1_cell)
    config_path = output.with_name(output.stem + ".config.yaml")
    _write_yaml(config_path, saved_config)
    summary: dict = {"output": str(output), "poses": len(scans), "method": method}
    summary["invalid_ranges"] = scans.invalid_ranges  # skipped (kiseki.scans' rule)
    lines = [f"{output}: {len(scans)} poses; the log has no reference poses"]
    if scans.has_reference_poses:
        position = ape(trajectory, scans.poses)
        heading = ape(trajectory, scans.poses, "rotation_deg")
        summary.update(position_rmse_m=position.rmse, position_max_m=position.max)
        summary.update(heading_rmse_deg=heading.rmse)
        lines = [
            f"{output}: {len(scans)} poses; {method}: position RMSE {position.rmse:.3f} m "
            f"(max {position.max:.3f} m), heading RMSE {heading.rmse:.2f} deg"
        ]
    lines[0] += f"; {scans.invalid_ranges} invalid range readings skipped"
    if not global_start and tracked.budget is not None:
        source = cost_model if cost_model is not None else _cost_path(output)
        if cost_model is None:
            tracked.cost_model.save(source)
        lines.append(f"{tracked.budget.describe()}; cost model: {source}")
        summary.update(budget=asdict(tracked.budget), cost_model_file=str(source))
    if global_start:
        report_path = write_report(result, output.with_suffix(".json"))
        lines.append(describe(result.report) + f" (report: {report_path})")
        summary.update(report_file=str(report_path), convergence=result.report.to_dict())
    _print_report(lines, summary, as_json)
    if global_start and plot is not None:
        render_global(grid, result, plot, title=f"{log.name}: global {method}")


def _cost_path(output: Path) -> Path:
    """Where a calibrated cost model is written: OUTPUT-STEM.cost.json beside the output."""
    return output.with_name(output.stem + ".cost.json")


def _given(**settings) -> dict:
    """The settings the command line gave (not None): the others keep their config's default,
    so that each default lives in one place (LocalizeConfig, GlobalConfig)."""
    return {name: value for name, value in settings.items() if value is not None}


def _print_report(lines: list[str], summary: dict, as_json: bool) -> None:
    """A command's report: its sentences for people (never wrapped when piped, so each stays
    one line for grep), or the same numbers as one JSON object with --json."""
    if as_json:
        show_fields("", summary, as_json=True)
    elif sys.stdout.isatty():
        for line in lines:
            console.print(line)
    else:
        for line in lines:
            typer.echo(line)


def _write_trajectory(
    output: Path, times: np.ndarray, trajectory: np.ndarray, reliability: np.ndarray
) -> None:
    rows = np.column_stack([times, trajectory, reliability])
    text = "t,x,y,theta,reliability\n" + "\n".join(
        ",".join(f"{v:.6f}" for v in row) for row in rows
    )
    atomic_write(output, lambda tmp: Path(tmp).write_text(text + "\n", encoding="utf-8"))


def _write_yaml(path: Path, doc: dict) -> None:
    def plain(value):
        if isinstance(value, tuple | list):
            return [plain(v) for v in value]
        if isinstance(value, np.generic):
            return value.item()
        return value

    text = yaml.safe_dump({k: plain(v) for k, v in doc.items()}, sort_keys=False)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
