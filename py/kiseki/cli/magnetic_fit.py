# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic fit``: a magnetic field map by Gaussian-process regression (thesis ch. 6)
from measurements; the ``kiseki magnetic`` group (kiseki.cli.magnetic) runs it."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.numbers_text import parse_float
from kiseki._support.options import CELL_LIMITS, Count, Metres, Seed, refuse_given
from kiseki.datasets.magnetic import concatenate_samples, read_magnetic_data
from kiseki.gp import (
    CurlFreeKernel,
    SquaredExponential,
    fit_curl_free_hyperparameters,
    fit_hyperparameters,
    hilbert_basis_size,
    spectral_tolerance,
)
from kiseki.gp.kernel import subsample
from kiseki.magnetic.binning import bin_readings
from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData
from kiseki.magnetic.map_cells import MAX_CELLS, cell_span
from kiseki.magnetic.map_folder import check_map_destination
from kiseki.magnetic.map_gp import (
    METHODS,
    MODELS,
    fit_component_gps,
    hilbert_settings,
    predictor_state,
)

__all__ = ["KERNEL_LIMITS", "fit"]

console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)
EXACT_LIMIT = 10_000  # beyond this many measurements the default is the reduced-rank GP
HILBERT_LIMIT = 20_000  # and beyond this many basis functions (HilbertGP's cap) the tiled GP
# The curl-free model's defaults are gp-aalto-defaults' pick (leave-one-run-out on both Aalto
# sensors: the lowest mean held-out RMSE among the methods that use every reading given): the
# exact curl-free GP on readings averaged per 0.1 m cell, its hyperparameters by marginal
# likelihood on 400 of them. Its factor is (3n)^2 doubles: 2,000 cells keep it at 288 MB, and
# beyond them the reduced-rank curl-free GP (kiseki.magnetic.map_gp.CURL_FREE_BASIS functions).
CURL_FREE_BIN = 0.1  # m
CURL_FREE_FIT_POINTS = 400
CURL_FREE_EXACT_LIMIT = 2_000
CURL_FREE_EXACT_MAX = 6_000  # --method exact refused beyond: a 2.6 GB factor


# --kernel's numbers (kiseki.gp.SquaredExponential): the signal and noise SDs in the data's units
# (uT or G), the length scale in metres. 1e-6..1e6 spans a picotesla to a tesla (in uT) and a
# micrometre to 1,000 km, and keeps what the GP computes with, their squares (1e-12..1e12) and
# d^2 / l^2, far from a double's overflow (1e200 squared is inf) and underflow (1e-200 squared
# is 0: a noise-free kernel whose matrix cannot be factorised)
KERNEL_LIMITS = (1e-6, 1e6)  # as the message writes them: [1e-6, 1e6]
_UNITS = "the data's units"
_KERNEL_PARTS = {
    "independent": (("sigma_f", _UNITS), ("l", "m"), ("sigma_n", _UNITS)),
    # the potential's sigma_f is in units times metres: sigma_f / l is the anomaly's SD
    "curl-free": (("sigma_f", "units x m"), ("l", "m"), ("sigma_lin", _UNITS), ("sigma_n", _UNITS)),
}


def _parse_kernel(text: str, model: str):
    """The kernel --kernel gives for `model` (SIGMA_F,L,SIGMA_N, or SIGMA_F,L,SIGMA_LIN,SIGMA_N
    for the curl-free one); a ValueError naming --kernel and the number outside
    :data:`KERNEL_LIMITS`."""
    parts = text.split(",")
    names = _KERNEL_PARTS[model]
    try:
        values = [parse_float(v.strip()) for v in parts]  # 1_0 is not 10
    except ValueError:
        values = []
    if len(values) != len(names):
        listed = ",".join(n for n, _ in names)
        raise ValueError(
            f"--kernel must be {len(names)} numbers {listed} (--model {model}), got {text.strip()}"
        )
    lo, hi = KERNEL_LIMITS
    for (name, unit), part, value in zip(names, parts, values, strict=True):
        if not lo <= value <= hi:  # a NaN never is
            raise ValueError(
                f"--kernel: {name} must be a number in [1e-6, 1e6] ({unit}), got {part.strip()}"
            )
    return CurlFreeKernel(*values) if model == "curl-free" else SquaredExponential(*values)


def _check_fit_options(ctx: typer.Context, kernel, max_points, method, units, model) -> None:
    """The fit's words and what its numbers do not apply to (the numbers have their ranges)."""
    if model not in MODELS:
        raise ValueError(f"--model must be curl-free or independent, got {model!r}")
    if model == "curl-free":  # one potential for the three components
        refuse_given(ctx, ["per_component"], "with --model curl-free (one potential)")
    if kernel is not None:  # the given hyperparameters: no search, so nothing per component
        refuse_given(ctx, ["per_component"], "with --kernel (its hyperparameters are given)")
        if max_points is None:  # no search and no subsample: nothing random
            refuse_given(ctx, ["seed"], "with --kernel and without --max-points (nothing random)")
    if method is not None and method not in METHODS:
        raise ValueError(f"--method must be exact, hilbert or tiled, got {method!r}")
    if method == "tiled" and model == "curl-free":
        raise ValueError(
            "--method tiled is for --model independent (the curl-free GP is not tiled)"
        )
    if units is not None and units not in ("uT", "G"):
        raise ValueError(f"--units must be uT or G, got {units!r}")


def _read_data(data: list[Path], units: str | None, dimension: int | None):
    """(positions, field, height, units) of DATA, positions in the map's dimension (a 2-D map
    of 3-D data: x, y, and the height is the median z)."""
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


def _fit_gps(x, y, kernel, per_component: bool, method: str, seed: int, model: str, default: bool):
    """(GPs, kernels, method, seconds for the hyperparameters, seconds for the fit); with
    `default` (no --method given) the independent model's reduced-rank GP becomes the tiled GP
    where one box would need too many basis functions at the fitted length scale."""
    if model == "curl-free":
        start = time.perf_counter()
        if kernel is None:  # the log marginal likelihood's maximum on a seeded subsample
            found = fit_curl_free_hyperparameters(x, y, max_points=CURL_FREE_FIT_POINTS, seed=seed)
            kernel = found.kernel
        hyper = time.perf_counter() - start
        start = time.perf_counter()
        gps = fit_component_gps(x, y, kernel, method)
        return gps, [kernel], method, hyper, time.perf_counter() - start
    columns = [slice(k, k + 1) for k in range(3)] if per_component else [slice(0, 3)]
    start = time.perf_counter()
    if kernel is not None:
        kernels = [kernel] * len(columns)
    else:  # maximise the log marginal likelihood (eqs. 6.11-6.15)
        kernels = [fit_hyperparameters(x, y[:, c], seed=seed).kernel for c in columns]
    hyper = time.perf_counter() - start
    if default and method == "hilbert" and _one_box_basis(x, kernels) > HILBERT_LIMIT:
        method = "tiled"
    start = time.perf_counter()
    # a tiled GP's tiles are factorised as the map's cells reach them, each freed after its
    # cells (kiseki.magnetic.map_gp.evaluate_on_cells): one tile's factor in memory at a time
    gps = fit_component_gps(x, y, kernels, method, build=method != "tiled")
    return gps, kernels, method, hyper, time.perf_counter() - start


def _check_map_size(data: list[Path], x: np.ndarray, margin: float, resolution: float) -> None:
    """The map's cells over the readings' box plus ``margin``, counted as
    MagneticFieldMap.from_gp counts them, within its MAX_CELLS before the fit; a ValueError
    naming the data otherwise (a reading 1e8 m from the others was refused after the fit, in a
    message naming no file)."""
    try:
        counts = cell_span(x.min(axis=0) - margin, x.max(axis=0) + margin, resolution)[2]
    except ValueError as err:
        raise ValueError(f"{', '.join(map(str, data))}: {err}") from None
    if np.prod(counts.astype(float)) > MAX_CELLS:
        span = " x ".join(f"{s:.6g}" for s in np.ptp(x, axis=0))
        raise ValueError(
            f"{', '.join(map(str, data))}: the readings span {span} m: a map of "
            f"{' x '.join(f'{c:.0f}' for c in counts)} cells of {resolution:g} m is more than "
            f"{MAX_CELLS:,} cells; choose a coarser --resolution or leave out the far readings"
        )


def _default_method(model: str, points: int) -> str:
    limit = CURL_FREE_EXACT_LIMIT if model == "curl-free" else EXACT_LIMIT
    return "exact" if points <= limit else "hilbert"


def _one_box_basis(x: np.ndarray, kernels) -> int:
    """The largest basis size of the HilbertGPs of these kernels on the data's default box (4
    length scales around it), each at its default spectral tolerance."""
    sides = np.ptp(x, axis=0)
    return max(
        hilbert_basis_size(sides + 8 * k.length_scale, k.length_scale, spectral_tolerance(k))
        for k in kernels
    )


@guarded(inputs=("data",), output_folders=("output",))  # replaced whole
@interruptible()
def fit(
    ctx: typer.Context,
    data: list[Path] = typer.Argument(
        ...,
        help="Measurements: Aalto run prefixes DIR/N (DIR/N-loc.csv, -mag.csv, -time.csv), CSV "
        "files with columns x,y[,z],mx,my,mz, or .mat hand-held walks.",
    ),
    output: Path = typer.Option(
        ..., "-o", "--output", help="Map folder to write (an earlier map there is replaced)."
    ),
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
    model: str = typer.Option(
        "curl-free",
        help="curl-free (the field as the gradient of a potential plus a constant, Solin et al. "
        "2018; kiseki's default, chosen by leave-one-run-out on the Aalto data) or independent "
        "(mx, my, mz as separate GPs, the thesis' ch. 6).",
    ),
    per_component: bool = typer.Option(
        False,
        "--per-component",
        help="Own hyperparameters for each of mx, my, mz (--model independent).",
    ),
    kernel: str | None = typer.Option(
        None,
        help="independent: sigma_f,l,sigma_n; curl-free: sigma_f,l,sigma_lin,sigma_n; each in "
        "[1e-6, 1e6] (SDs in the data's units, the potential's sigma_f in units x m, l in m; "
        "default: maximise the log marginal likelihood).",
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
        None,
        help="exact, hilbert (reduced rank) or tiled (a grid of overlapping GPs, --model "
        f"independent); default: exact up to {EXACT_LIMIT:,} measurements "
        f"({CURL_FREE_EXACT_LIMIT:,} for the curl-free model), then hilbert, and tiled where one "
        f"reduced-rank GP would need over {HILBERT_LIMIT:,} basis functions.",
    ),
    units: str | None = typer.Option(None, help="uT or G: the units of CSV data."),
    bin_size: float | None = typer.Option(
        None,
        "--bin",
        parser=Metres("--bin", *CELL_LIMITS),
        help="Average the readings per cell of this size (m) first, one reading per place (the "
        "thesis stores its 3-D survey per 0.2 m voxel); default: "
        f"{CURL_FREE_BIN} m for the curl-free model, none for the independent one.",
    ),
) -> None:
    """Fit a GP to magnetic measurements and write the map of its mean and variance (the
    data's bounding box plus --margin), with the measurements for exact predictions.

    Example: kiseki magnetic fit aalto/invensense/1 aalto/invensense/2 -o hall-map
    """
    _check_fit_options(ctx, kernel, max_points, method, units, model)
    fixed = _parse_kernel(kernel, model) if kernel is not None else None
    check_map_destination(output, "-o")  # before the fit: a user's file in it is refused
    x, y, height, units = _read_data(data, units, dimension)
    n_read = len(x)
    if bin_size is None and model == "curl-free":
        bin_size = CURL_FREE_BIN
    if bin_size is not None:
        x, y, _ = bin_readings(x, y, bin_size)
    if max_points is not None and len(x) > max_points:  # after --bin: of the cells' readings
        keep = subsample(len(x), max_points, seed)
        x, y = x[keep], y[keep]
    _check_map_size(data, x, margin, resolution)
    default = method is None
    method = method or _default_method(model, len(x))
    if model == "curl-free" and method == "exact" and len(x) > CURL_FREE_EXACT_MAX:
        raise ValueError(
            f"--method exact: {len(x):,} readings need a {72 * len(x) ** 2 / 1e9:.1f} GB "
            f"curl-free factor (at most {CURL_FREE_EXACT_MAX:,}); use --method hilbert or a "
            "larger --bin"
        )
    try:  # a fit the data cannot give (too few or coincident readings) names the data
        gps, kernels, method, t_hyper, t_fit = _fit_gps(
            x, y, fixed, per_component, method, seed, model, default
        )
    except (ValueError, RuntimeError) as err:
        raise ValueError(f"{', '.join(map(str, data))}: {err}") from None
    lml = [float(g.log_marginal_likelihood()) for g in gps if hasattr(g, "log_marginal_likelihood")]
    start = time.perf_counter()
    lower, upper = x.min(axis=0) - margin, x.max(axis=0) + margin
    mean = "zero" if model == "curl-free" else "constant"  # curl-free: the constant is a term
    hilbert = hilbert_settings(gps)
    training = TrainingData(x, y, method, mean, hilbert, predictor_state(gps[0]))
    provenance = {
        "data": {
            "sources": [str(d) for d in data],
            "points": n_read,
            "bin": bin_size,
            "used_points": len(x),
        },
        "fit": {
            "model": model,
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
    try:  # a box the map cannot take (beyond OctoMap's keys in 3-D) names the data
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
    except ValueError as err:
        raise ValueError(f"{', '.join(map(str, data))}: {err}") from None
    t_map = time.perf_counter() - start
    fmap.save(output)
    _report_fit(fmap, output, kernels, lml, len(x), n_read, (t_hyper, t_fit, t_map))


def _report_fit(fmap, output: Path, kernels, lml: list, used: int, read: int, seconds) -> None:
    names = ("mx, my, mz",) if len(kernels) == 1 else ("mx", "my", "mz")
    u = "" if fmap.units == "unknown" else f" {fmap.units}"
    if isinstance(kernels[0], CurlFreeKernel):
        k = kernels[0]
        console.print(
            f"curl-free potential: sigma_f {k.sigma_f:.4g}{u} m, length scale "
            f"{k.length_scale:.4g} m (anomaly SD {k.anomaly_sd:.4g}{u}), constant field SD "
            f"sigma_lin {k.sigma_lin:.4g}{u}, sigma_n {k.sigma_n:.4g}{u}"
        )
    else:
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
        f"({_describe(fmap.training.method, kernels)}); hyperparameters {t_hyper:.2f} s, "
        f"fit {t_fit:.2f} s, map {t_map:.2f} s"
    )


def _describe(method: str, kernels) -> str:
    if isinstance(kernels[0], CurlFreeKernel):
        return "exact curl-free GP" if method == "exact" else "reduced-rank curl-free GP"
    return f"{method} GP"
