# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic``: magnetic field maps by Gaussian-process regression (thesis ch. 6), and
teaching and navigation along linear magnetic maps (ch. 3-4)."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._support.atomic import atomic_write
from kiseki._support.guard import Folder, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import Count, Fraction, Metres, Seed, refuse_given
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki._support.replaced_files import refuse_replacing
from kiseki.apps.magnetic.navigate_outputs import navigate_folder, teach_folder
from kiseki.cli.magnetic_fit import fit
from kiseki.datasets.kok import read_kok_walk
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.loop_travel_distance import STARTS, LoopTravelConfig
from kiseki.magnetic.loop_walk import localize_walk_loop
from kiseki.magnetic.points_csv import read_points
from kiseki.magnetic.render import picture_size, render_field_map
from kiseki.magnetic.travel_distance_walk import WalkOdometry, localize_walk

__all__ = ["app"]

app = typer.Typer(
    no_args_is_help=True,
    help="Magnetic field maps (fit, predict, render), walks, teaching and navigation.",
)
app.command("fit")(fit)  # first in the listing: the map the other commands read
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)
# what kiseki magnetic walk and navigate write in their -o folders (kiseki._support.guard);
# an existing one is replaced only with --overwrite (kiseki._support.replaced_files)
_WALK = Folder("output", ("trajectory.csv",))
_NAVIGATION = Folder("output", ("run.mcap", "navigation.csv", "navigation.png"))
_OVERWRITE = "give --overwrite, or another folder"


@app.command("predict")
@guarded(inputs=("map_folder", "at"), outputs=("output",))
@interruptible()
def predict(
    ctx: typer.Context,
    map_folder: Path = typer.Argument(..., metavar="MAP", help="Map folder (kiseki magnetic fit)."),
    at: Path = typer.Option(..., "--at", help="CSV with a header and columns x,y[,z]."),
    output: Path = typer.Option(..., "-o", "--output", help="CSV to write."),
    interpolate: bool = typer.Option(
        False, "--interpolate", help="Interpolate the map's grid even when it keeps its data."
    ),
) -> None:
    """Mean and variance of the field at points: columns x,y[,z],mx,my,mz,var_mx,var_my,var_mz
    (variances of the noise-free field, in the map's units squared). A map that keeps its
    measurements re-evaluates the GP exactly at each point (eqs. 6.8-6.9); otherwise, or with
    --interpolate, the grid is interpolated (the GP prior outside the map).

    Example: kiseki magnetic predict hall-map --at points.csv -o field.csv"""
    fmap = MagneticFieldMap.load(map_folder)
    if fmap.training is None:
        refuse_given(ctx, ["interpolate"], f"to {map_folder}: it keeps no data to re-evaluate")
    points, dropped = read_points(at, fmap.dimension)
    exact = fmap.training is not None and not interpolate
    start = time.perf_counter()
    # asked once: a tiled map's tiles are freed as their points are done
    mean, var = fmap.predict(points, release=True) if exact else fmap.value_at(points)
    seconds = time.perf_counter() - start
    header = ",".join([*"xyz"[: fmap.dimension], "mx", "my", "mz", "var_mx", "var_my", "var_mz"])
    rows = np.column_stack([points, mean, var])
    text = header + "\n" + "\n".join(",".join(f"{v:.9g}" for v in r) for r in rows) + "\n"
    atomic_write(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    stored = fmap.training is not None and fmap.training.predictor is not None
    source = "its stored factor" if stored else "rebuilt from its readings, no optimisation"
    how = f"the GP re-evaluated exactly ({source})" if exact else "interpolated from the grid"
    console.print(
        f"{output}: {len(points):,} points, {how} ({seconds:.2f} s); field in {fmap.units}"
    )
    if dropped:
        console.print(f"  the z column of {at} is ignored: the map is 2-D (height {fmap.height})")


@app.command("render")
@guarded(inputs=("map_folder",), outputs=("output",))
@interruptible()
def render(
    ctx: typer.Context,
    map_folder: Path = typer.Argument(..., metavar="MAP", help="Map folder (kiseki magnetic fit)."),
    output: Path = typer.Option(..., "-o", "--output", help="PNG to write."),
    # a row of six 300 px panels each: 100 rows are a picture 30,060 px high
    slices: int = typer.Option(
        4,
        parser=Count("--slices", 1, 100),
        help="3-D maps: horizontal slices drawn (one row each).",
    ),
) -> None:
    """Draw the mean and variance of mx, my, mz as six panels with colour bars (the thesis'
    Fig. 6.13: 1500 x 800 px); a 3-D map as one row of six per slice height (Fig. 6.14).

    Example: kiseki magnetic render hall-map -o hall-map.png"""
    if output.suffix.lower() != ".png":
        raise ValueError(f"-o {output}: the picture is a PNG: give a .png file")
    check_suffix("-o", output, FIGURE_SUFFIXES)
    fmap = MagneticFieldMap.load(map_folder)
    if fmap.dimension == 2:
        refuse_given(ctx, ["slices"], f"to {map_folder}: a 2-D map (slices are 3-D maps')")
    render_field_map(fmap, output, slices)
    width, height = picture_size(fmap, slices)
    console.print(f"{output}: {width} x {height} px")


@app.command("walk")
@guarded(inputs=("walk_file",), output_folders=(_WALK,))
@interruptible()
def walk(
    walk_file: Path = typer.Argument(
        ..., metavar="WALK.mat", help="Hand-held walk of repeated laps (Kok-Solin .mat layout)."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for trajectory.csv."),
    seed: int = typer.Option(
        0, parser=Seed(), help="Seed of the odometry's scale error and noise and the filter."
    ),
    # -100 % stops the odometry; +100 % doubles every step
    scale_error: float | None = typer.Option(
        None,
        parser=Fraction("--scale-error", -1, 1, lo_open=True),
        help="Fixed odometry scale error e (default: drawn from N(0, 0.05^2)).",
    ),
    filter_name: str = typer.Option(
        "loop",
        "--filter",
        help="loop (kiseki's: the walk as one stream, no lap boundaries) or thesis.",
    ),
    start: str = typer.Option(
        LoopTravelConfig.start,
        help="With --filter loop: known (the loop's start) or global (anywhere on it).",
    ),
    overwrite: bool = typer.Option(
        False, help="Replace an existing output trajectory.csv in the folder."
    ),
) -> None:
    """Travel distance along a real walk's loop from odometry and the magnetic field. The first
    lap (until the walker comes back within 1.5 m of the start after 10 m) is the map.

    --filter loop (default), kiseki's loop filter: everything after the first lap is one
    stream of odometry and readings (vertical field and horizontal magnitude, which do not
    turn with the heading), weighed by a Gaussian process of the first lap; the odometry's
    scale is estimated; no lap boundary is given to it. s_odom is the odometry continued from
    the same start, around the loop; errors are taken around the loop.

    --filter thesis: the thesis' travel-distance particle filter (sec. 4.4.1: 1000
    particles, w = 1/(a s + 1), a = 50 per G m, l = 6 m of mz, resampling when ESS < 9n/10):
    the later laps are localized each from travel distance 0, their starts taken from the
    walk's positions. It compares mz, the vertical field (the walk's quaternions turn the
    readings to the world frame). Laps that leave the map's path (over 2 m from every map
    node) are reported and not localized.

    Odometry after the first lap: each horizontal ARKit step |dp| becomes
    (1 + e) |dp| + N(0, (0.1 |dp|)^2), e drawn once from N(0, 0.05^2) by the seed. The walk's
    positions are used to map the first lap and to score, never by --filter loop to localize.
    Writes OUT/trajectory.csv (t,s_true,s_est,s_odom[,scale]; s_true from the map node nearest
    the true position; an existing one is replaced only with --overwrite) and prints the RMSE
    of s_est and s_odom.

    Example: kiseki magnetic walk eight.mat -o eight-walk --seed 0"""
    target = output / "trajectory.csv"
    if filter_name not in ("loop", "thesis"):
        raise ValueError(f"--filter must be loop or thesis, got {filter_name!r}")
    if start not in STARTS:
        raise ValueError(f"--start must be {' or '.join(STARTS)}, got {start!r}")
    if not overwrite:
        refuse_replacing(output, _WALK.writes, "-o", _OVERWRITE)
    if filter_name == "loop":
        _walk_loop(walk_file, target, seed, scale_error, start)
        return
    if start != LoopTravelConfig.start:
        raise ValueError("--start is for --filter loop (the thesis' laps start at the map's start)")
    result = _of_walk(walk_file, localize_walk, seed, WalkOdometry(scale_error=scale_error))
    for lap, t, metres in result.off_path:
        console.print(
            f"lap {lap} leaves the map's path ({metres:.2f} m from the nearest map node at "
            f"t = {t:.1f} s): not localized"
        )
    if result.t.size == 0:
        raise ValueError(f"{walk_file}: every later lap leaves the map's path: nothing localized")
    rows = np.column_stack([result.t, result.s_true, result.s_est, result.s_odom])
    text = "t,s_true,s_est,s_odom\n" + "".join(",".join(f"{v:.6f}" for v in r) + "\n" for r in rows)
    output.mkdir(parents=True, exist_ok=True)
    atomic_write(target, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    laps = len(result.laps) - 1 - len(result.off_path)
    console.print(
        f"{target}: {len(rows)} samples of {laps} lap(s) against a map of "
        f"{len(result.linear_map)} nodes; odometry scale error {result.scale_error:+.4f}"
    )
    console.print(f"RMSE s_est {result.rmse('s_est'):.3f} m, s_odom {result.rmse('s_odom'):.3f} m")


def _of_walk(walk_file: Path, localize, *args):
    """``localize(walk, *args)`` on the walk read from ``walk_file``; what it finds wrong with
    the walk's own data (no lap, one lap only) names the file ('walk: the walker never comes
    back ...' did not)."""
    walk = read_kok_walk(walk_file)
    try:
        return localize(walk, *args)
    except ValueError as err:
        raise ValueError(f"{walk_file}: {err}") from None


def _walk_loop(walk_file: Path, target: Path, seed: int, scale_error, start: str) -> None:
    """kiseki's loop filter on a walk (``kiseki magnetic walk --filter loop``)."""
    odometry = WalkOdometry(scale_error=scale_error)
    result = _of_walk(walk_file, localize_walk_loop, seed, odometry, LoopTravelConfig(start=start))
    if result.t.size == 0:
        raise ValueError(f"{walk_file}: every later sample leaves the map's path: nothing scored")
    rows = np.column_stack([result.t, result.s_true, result.s_est, result.s_dr, result.scale])
    text = "t,s_true,s_est,s_odom,scale\n" + "".join(
        ",".join(f"{v:.6f}" for v in r) + "\n" for r in rows
    )
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(target, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    kernels = ", ".join(
        f"{name} l {p.kernel.length_scale:.2f} m, sigma_n {100 * p.kernel.sigma_n:.2f} uT"
        for name, p in zip(("m_z", "|m_h|"), result.profiles, strict=True)
    )
    console.print(
        f"{target}: {len(rows)} samples after a mapping lap of {result.length:.4f} m "
        f"({kernels}); odometry scale error {result.scale_error:+.4f}, estimated scale "
        f"{result.scale[-1]:.4f}"
    )
    console.print(f"RMSE s_est {result.rmse('s_est'):.3f} m, s_odom {result.rmse('s_dr'):.3f} m")


@app.command("teach")
@guarded(inputs=("scene",), output_folders=("output",))
@interruptible()
def teach(
    scene: Path = typer.Argument(..., help="Scene file with a route (its teach variant)."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the linear maps."),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the teaching runs."),
    # the thesis' parallel paths are 1 m apart; 10 m is wider than a corridor's route needs
    offset: float = typer.Option(
        1.0,
        parser=Metres("--offset", 0, 10, lo_open=True),
        help="m between the taught path and its parallel paths.",
    ),
) -> None:
    """Teaches a route by hand (thesis ch. 3-4): the linear magnetic map of the route (nodes
    every 0.1 m) and of two paths OFFSET m to its left and right (Rahok's eq. 3.1), written to
    OUT (a linear-map folder; left/ and right/; the teaching runs in runs/).

    Example: kiseki magnetic teach data/worlds/magnetic_path.yaml -o taught"""
    maps = teach_folder(scene, output, seed, offset)
    console.print(f"{output}: {len(maps.center)} nodes over {maps.center.s[-1]:.1f} m")


@app.command("navigate")
@guarded(inputs=("scene", "map_folder"), output_folders=(_NAVIGATION,))
@interruptible()
def navigate(
    scene: Path = typer.Argument(..., help="Scene file (its playback variant is driven)."),
    map_folder: Path = typer.Option(..., "--map", help="Folder of kiseki magnetic teach."),
    navigator: str = typer.Option(
        "multi", help="rahok|magnetic-geometric|magnetic|geometric|odometry|multi."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the run and plots."),
    seed: int = typer.Option(1, parser=Seed(), help="Seed of the playback run."),
    gates: str = typer.Option(
        "thesis", help="Magnetic navigators' validity: thesis (r_z >= 0.998) or sensor."
    ),
    overwrite: bool = typer.Option(
        False, help="Replace an existing output run.mcap, navigation.csv or navigation.png."
    ),
) -> None:
    """Plays the taught route back steering with one navigator (thesis ch. 3: rahok; ch. 4:
    the four navigators alone, or multi, arbitrated by priority). Writes OUT/run.mcap,
    OUT/navigation.csv and OUT/navigation.png (path, cross-track error, priority history);
    existing ones are replaced only with --overwrite.
    --gates sensor: the magnetic navigators are valid while |m_z,n - m_z,t| <= 3 sigma
    sqrt(1 + 1/c_n), sigma the sensor's noise read from the taught map, c_n the readings its
    node averaged (kiseki's rule; the thesis' r_z >= 0.998 passes 0.002 G).

    Example: kiseki magnetic navigate data/worlds/magnetic_path.yaml --map taught -o nav"""
    if not overwrite:
        refuse_replacing(output, _NAVIGATION.writes, "-o", _OVERWRITE)
    r = navigate_folder(scene, map_folder, navigator, output, seed, gates)
    off = np.abs(r.cross_track)
    console.print(
        f"{output}: {navigator} {'reached' if r.reached_goal else 'did not reach'} the goal;"
        f" |cross-track| mean {off.mean():.2f} m, max {off.max():.2f} m"
    )
