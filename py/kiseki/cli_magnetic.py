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

from kiseki._support.guard import Folder, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import CELL_LIMITS, Count, Fraction, Metres, Seed, refuse_given
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix

__all__ = ["magnetic_app"]

magnetic_app = typer.Typer(
    no_args_is_help=True,
    help="Magnetic field maps (fit, predict, render), walks, teaching and navigation.",
)
console = Console(soft_wrap=True)
# what kiseki magnetic navigate writes in its -o folder (kiseki._support.guard)
_NAVIGATION = Folder("output", ("run.mcap", "navigation.csv", "navigation.png"))
EXACT_LIMIT = 10_000  # beyond this many measurements the default is the reduced-rank GP
METHODS = ("exact", "hilbert")


# --kernel's numbers (kiseki.gp.SquaredExponential): the signal and noise SDs in the data's units
# (uT or G), the length scale in metres. 1e-6..1e6 spans a picotesla to a tesla (in uT) and a
# micrometre to 1,000 km, and keeps what the GP computes with, their squares (1e-12..1e12) and
# d^2 / l^2, far from a double's overflow (1e200 squared is inf) and underflow (1e-200 squared
# is 0: a noise-free kernel whose matrix cannot be factorised)
KERNEL_LIMITS = (1e-6, 1e6)  # as the message writes them: [1e-6, 1e6]
_KERNEL_PARTS = (("sigma_f", "the data's units"), ("l", "m"), ("sigma_n", "the data's units"))


def _parse_kernel(text: str):
    """The kernel --kernel SIGMA_F,L,SIGMA_N gives; a ValueError naming --kernel and the number
    outside :data:`KERNEL_LIMITS`."""
    from kiseki.gp import SquaredExponential

    parts = text.split(",")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        values = []
    if len(values) != 3:
        raise ValueError(f"--kernel must be three numbers sigma_f,l,sigma_n, got {text.strip()}")
    lo, hi = KERNEL_LIMITS
    for (name, unit), part, value in zip(_KERNEL_PARTS, parts, values, strict=True):
        if not lo <= value <= hi:  # a NaN never is
            raise ValueError(
                f"--kernel: {name} must be a number in [1e-6, 1e6] ({unit}), got {part.strip()}"
            )
    return SquaredExponential(*values)


def _check_fit_options(ctx: typer.Context, kernel, max_points, method, units) -> None:
    """The fit's words and what its numbers do not apply to (the numbers have their ranges)."""
    if kernel is not None:  # the given hyperparameters: no search, so nothing per component
        refuse_given(ctx, ["per_component"], "with --kernel (its hyperparameters are given)")
        if max_points is None:  # no search and no subsample: nothing random
            refuse_given(ctx, ["seed"], "with --kernel and without --max-points (nothing random)")
    if method is not None and method not in METHODS:
        raise ValueError(f"--method must be exact or hilbert, got {method!r}")
    if units is not None and units not in ("uT", "G"):
        raise ValueError(f"--units must be uT or G, got {units!r}")


def _read_data(data: list[Path], units: str | None, dimension: int | None):
    """(positions, field, height, units) of DATA, positions in the map's dimension (a 2-D map
    of 3-D data: x, y, and the height is the median z)."""
    from kiseki.datasets.magnetic import concatenate_samples, read_magnetic_data

    samples = concatenate_samples([read_magnetic_data(d) for d in data])
    if units is not None and samples.units not in ("unknown", units):
        raise ValueError(f"--units {units}: the data state their units as {samples.units}")
    x, height = np.asarray(samples.positions), None
    dimension = dimension or samples.dimension
    if dimension == 3 and samples.dimension == 2:
        raise ValueError(f"--dimension 3: {samples.source} has 2-D positions (no z)")
    if dimension == 2 and samples.dimension == 3:
        height, x = float(np.median(x[:, 2])), x[:, :2]
    return x, np.asarray(samples.field), height, units or samples.units


def _fit_gps(x, y, kernel, per_component: bool, method: str, seed: int):
    """(GPs, kernels, seconds for the hyperparameters, seconds for the fit)."""
    from kiseki.gp import fit_hyperparameters
    from kiseki.magnetic.field_map import fit_component_gps

    columns = [slice(k, k + 1) for k in range(3)] if per_component else [slice(0, 3)]
    start = time.perf_counter()
    if kernel is not None:
        kernels = [kernel] * len(columns)
    else:  # maximise the log marginal likelihood (eqs. 6.11-6.15)
        kernels = [fit_hyperparameters(x, y[:, c], seed=seed).kernel for c in columns]
    hyper = time.perf_counter() - start
    start = time.perf_counter()
    gps = fit_component_gps(x, y, kernels, method)
    return gps, kernels, hyper, time.perf_counter() - start


def _hilbert_settings(gp) -> dict | None:
    """The reduced-rank GP's box, so that predictions rebuild the same GP."""
    if not hasattr(gp, "lower"):
        return None
    return {"domain": [np.asarray(gp.lower).tolist(), np.asarray(gp.upper).tolist()]}


@magnetic_app.command("fit")
@guarded(inputs=("data",), output_folders=("output",))  # replaced whole
@interruptible()
def fit(
    ctx: typer.Context,
    data: list[Path] = typer.Argument(
        ...,
        help="Measurements: Aalto run prefixes DIR/N (DIR/N-loc.csv, -mag.csv, -time.csv), CSV "
        "files with columns x,y[,z],mx,my,mz, or .mat hand-held walks.",
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Map folder to write."),
    dimension: int | None = typer.Option(
        None,
        parser=Count("--dimension", 2, 3),
        help="2 (grid over x, y) or 3 (voxels); default: the data's.",
    ),
    resolution: float = typer.Option(
        0.1, parser=Metres("--resolution", *CELL_LIMITS), help="Cell (voxel) size in metres."
    ),
    # a kilometre around the data at most; the cells of the whole box then have their limit
    margin: float = typer.Option(
        0.5,
        parser=Metres("--margin", 0, 1000),
        help="Metres added around the data's bounding box.",
    ),
    per_component: bool = typer.Option(
        False, "--per-component", help="Own hyperparameters for each of mx, my, mz."
    ),
    kernel: str | None = typer.Option(
        None,
        help="sigma_f,l,sigma_n, each in [1e-6, 1e6] (SDs in the data's units, l in m; default: "
        "maximise the log marginal likelihood).",
    ),
    # a GP needs a few points; 10^8 readings of (x, y, z, mx, my, mz) are 4.8 GB of doubles
    max_points: int | None = typer.Option(
        None,
        parser=Count("--max-points", 4, 100_000_000),
        help="Fit on a seeded random subsample of this many measurements.",
    ),
    seed: int = typer.Option(
        0, parser=Seed(), help="Seed of the subsample and the optimizer's restarts."
    ),
    method: str | None = typer.Option(
        None, help=f"exact or hilbert (default: exact up to {EXACT_LIMIT:,} measurements)."
    ),
    units: str | None = typer.Option(None, help="uT or G: the units of CSV data."),
    bin_size: float | None = typer.Option(
        None,
        "--bin",
        parser=Metres("--bin", *CELL_LIMITS),
        help="Average the readings per cell of this size (m) first, one reading per place (the "
        "thesis stores its 3-D survey per 0.2 m voxel); recommended for dense 50 Hz tracks.",
    ),
) -> None:
    """Fit a GP to magnetic measurements and write the map of its mean and variance (the
    data's bounding box plus --margin), with the measurements for exact predictions.

    Example: kiseki magnetic fit aalto/invensense/1 aalto/invensense/2 -o hall-map
    """
    from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData
    from kiseki.magnetic.map_folder import check_map_destination

    _check_fit_options(ctx, kernel, max_points, method, units)
    fixed = _parse_kernel(kernel) if kernel is not None else None
    check_map_destination(output)
    x, y, height, units = _read_data(data, units, dimension)
    n_read = len(x)
    if bin_size is not None:
        from kiseki.magnetic.binning import bin_readings

        x, y, _ = bin_readings(x, y, bin_size)
    if max_points is not None and len(x) > max_points:  # after --bin: of the cells' readings
        from kiseki.gp.kernel import subsample

        keep = subsample(len(x), max_points, seed)
        x, y = x[keep], y[keep]
    method = method or ("exact" if len(x) <= EXACT_LIMIT else "hilbert")
    gps, kernels, t_hyper, t_fit = _fit_gps(x, y, fixed, per_component, method, seed)
    lml = [float(g.log_marginal_likelihood()) for g in gps if hasattr(g, "log_marginal_likelihood")]
    start = time.perf_counter()
    lower, upper = x.min(axis=0) - margin, x.max(axis=0) + margin
    training = TrainingData(x, y, method, "constant", _hilbert_settings(gps[0]))
    provenance = {
        "data": {
            "sources": [str(d) for d in data],
            "points": n_read,
            "bin": bin_size,
            "used_points": len(x),
        },
        "fit": {
            "method": method,
            "per_component": per_component,
            "hyperparameters": "given"
            if fixed is not None
            else "maximised log marginal likelihood",
            "log_marginal_likelihood": lml or None,
            "seed": seed,
            "seconds": {"hyperparameters": round(t_hyper, 3), "fit": round(t_fit, 3)},
        },
    }
    fmap = MagneticFieldMap.from_gp(
        gps,
        lower,
        upper,
        resolution,
        height,
        units=units,
        provenance=provenance,
        training=training,
        progress=True,
    )
    t_map = time.perf_counter() - start
    fmap.save(output)
    _report_fit(fmap, output, kernels, lml, len(x), n_read, (t_hyper, t_fit, t_map))


def _report_fit(fmap, output: Path, kernels, lml: list, used: int, read: int, seconds) -> None:
    names = ("mx, my, mz",) if len(kernels) == 1 else ("mx", "my", "mz")
    u = "" if fmap.units == "unknown" else f" {fmap.units}"
    for c, k in zip(names, kernels, strict=True):
        console.print(
            f"{c}: sigma_f {k.sigma_f:.4g}{u}, length scale {k.length_scale:.4g} m, "
            f"sigma_n {k.sigma_n:.4g}{u}"
        )
    if lml:
        console.print(f"log marginal likelihood {sum(lml):.6g} (eq. 6.11)")
    t_hyper, t_fit, t_map = seconds
    console.print(
        f"{output}: {fmap.dimension}-D map, {' x '.join(map(str, fmap.cells))} cells of "
        f"{fmap.resolution:g} m from {used:,} of {read:,} measurements "
        f"({fmap.training.method} GP); hyperparameters {t_hyper:.2f} s, fit {t_fit:.2f} s, "
        f"map {t_map:.2f} s"
    )


@magnetic_app.command("predict")
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
    from kiseki._support.atomic import atomic_write
    from kiseki.magnetic.field_map import MagneticFieldMap
    from kiseki.magnetic.points_csv import read_points

    fmap = MagneticFieldMap.load(map_folder)
    if fmap.training is None:
        refuse_given(ctx, ["interpolate"], f"to {map_folder}: it keeps no data to re-evaluate")
    points, dropped = read_points(at, fmap.dimension)
    exact = fmap.training is not None and not interpolate
    start = time.perf_counter()
    mean, var = fmap.predict(points) if exact else fmap.value_at(points)
    seconds = time.perf_counter() - start
    header = ",".join([*"xyz"[: fmap.dimension], "mx", "my", "mz", "var_mx", "var_my", "var_mz"])
    rows = np.column_stack([points, mean, var])
    text = header + "\n" + "\n".join(",".join(f"{v:.9g}" for v in r) for r in rows) + "\n"
    atomic_write(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
    how = "the GP re-evaluated exactly" if exact else "interpolated from the grid"
    console.print(
        f"{output}: {len(points):,} points, {how} ({seconds:.2f} s); field in {fmap.units}"
    )
    if dropped:
        console.print(f"  the z column of {at} is ignored: the map is 2-D (height {fmap.height})")


@magnetic_app.command("render")
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
    from kiseki.magnetic.field_map import MagneticFieldMap
    from kiseki.magnetic.render import picture_size, render_field_map

    if output.suffix.lower() != ".png":
        raise ValueError(f"-o {output}: the picture is a PNG: give a .png file")
    check_suffix("-o", output, FIGURE_SUFFIXES)
    fmap = MagneticFieldMap.load(map_folder)
    if fmap.dimension == 2:
        refuse_given(ctx, ["slices"], f"to {map_folder}: a 2-D map (slices are 3-D maps')")
    render_field_map(fmap, output, slices)
    width, height = picture_size(fmap, slices)
    console.print(f"{output}: {width} x {height} px")


@magnetic_app.command("walk")
@guarded(inputs=("walk_file",), output_folders=(Folder("output", ("trajectory.csv",)),))
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
) -> None:
    """The thesis' travel-distance particle filter (sec. 4.4.1: 1000 particles, w = 1/(a s + 1),
    a = 50 per G m, l = 6 m of mz, resampling when ESS < 9n/10) on a real walk: the first lap
    (until the walker comes back within 1.5 m of the start after 10 m) is the linear map, the
    later laps are localized against it, each from travel distance 0. The filter compares mz,
    the vertical field (the walk's quaternions turn the readings to the world frame, so the map
    and the laps compare the same component however the iPad is held). Odometry of the later
    laps: each horizontal ARKit step
    |dp| becomes (1 + e) |dp| + N(0, (0.1 |dp|)^2), e drawn once from N(0, 0.05^2) by the seed.
    Writes OUT/trajectory.csv (t,s_true,s_est,s_odom; s_true from the map node nearest the true
    position) and prints the RMSE of s_est and s_odom. Laps that leave the map's path (over
    2 m from every map node) are reported and not localized.

    Example: kiseki magnetic walk eight.mat -o eight-walk --seed 0"""
    from kiseki._support.atomic import atomic_write
    from kiseki.datasets.kok import read_kok_walk
    from kiseki.magnetic.travel_distance_walk import WalkOdometry, localize_walk

    target = output / "trajectory.csv"
    result = localize_walk(read_kok_walk(walk_file), seed, WalkOdometry(scale_error=scale_error))
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


@magnetic_app.command("teach")
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
    from kiseki.apps.magnetic.navigate_outputs import teach_folder

    maps = teach_folder(scene, output, seed, offset)
    console.print(f"{output}: {len(maps.center)} nodes over {maps.center.s[-1]:.1f} m")


@magnetic_app.command("navigate")
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
) -> None:
    """Plays the taught route back steering with one navigator (thesis ch. 3: rahok; ch. 4:
    the four navigators alone, or multi, arbitrated by priority). Writes OUT/run.mcap,
    OUT/navigation.csv and OUT/navigation.png (path, cross-track error, priority history).

    Example: kiseki magnetic navigate data/worlds/magnetic_path.yaml --map taught -o nav"""
    from kiseki.apps.magnetic.navigate_outputs import navigate_folder

    r = navigate_folder(scene, map_folder, navigator, output, seed)
    off = np.abs(r.cross_track)
    console.print(
        f"{output}: {navigator} {'reached' if r.reached_goal else 'did not reach'} the goal;"
        f" |cross-track| mean {off.mean():.2f} m, max {off.max():.2f} m"
    )
