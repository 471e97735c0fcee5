# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures of a magnetic field map: the mean and variance of mx, my, mz as six panels (thesis
Fig. 6.13); a 3-D map as horizontal slices at several heights, one row of six panels per
height (Fig. 6.14)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki._support.atomic import atomic_write
from kiseki.magnetic.field_map import COMPONENTS, MagneticFieldMap
from kiseki.plots import new_figure

__all__ = ["render_field_map", "slice_indices", "picture_size"]

DPI = 100
PANEL_INCHES = (3.0, 3.0)  # width, height of one of the six panels (3-D rows)


def slice_indices(fmap: MagneticFieldMap, slices: int) -> list[int]:
    """Voxel layers (z indices) drawn for a 3-D map: `slices` evenly spread from the lowest to
    the highest layer (fewer when the map has fewer layers)."""
    if slices < 1:
        raise ValueError(f"slices must be at least 1, got {slices}")
    nz = fmap.mean.shape[0]
    return sorted({int(round(k)) for k in np.linspace(0, nz - 1, min(slices, nz))})


def picture_size(fmap: MagneticFieldMap, slices: int = 4) -> tuple[int, int]:
    """(width, height) in pixels of the PNG :func:`render_field_map` writes: 1500 x 800 for a
    2-D map; 1800 x (300 x rows + 60) for a 3-D map, one row per drawn slice."""
    if fmap.dimension == 2:
        return 1500, 800
    rows = len(slice_indices(fmap, slices))
    return 6 * int(PANEL_INCHES[0] * DPI), rows * int(PANEL_INCHES[1] * DPI) + 60


def _panel(ax, image, extent, cmap, vmin, vmax, title):
    shown = ax.imshow(
        image, origin="lower", extent=extent, cmap=cmap, vmin=vmin, vmax=vmax, aspect="equal"
    )
    ax.set_title(title, fontsize=9)
    ax.tick_params(labelsize=7)
    return shown


def _colour_bar(fig, shown, axes, label: str) -> None:
    bar = fig.colorbar(shown, ax=axes, shrink=0.85)
    bar.set_label(label, fontsize=8)
    bar.ax.tick_params(labelsize=7)


def _draw_row(axes, fmap, mean, var, extent, ranges, suffix: str) -> list:
    """Six panels, the means of mx, my, mz then their variances; returns their images."""
    shown = []
    for k, c in enumerate(COMPONENTS):
        lo, hi = ranges[k]
        shown.append(_panel(axes[k], mean[..., k], extent, "viridis", lo, hi, f"{c} mean{suffix}"))
    for k, c in enumerate(COMPONENTS):
        # from 0 to the prior sigma_f^2: where the data leave the field unknown
        top = float(fmap.prior_variance[k])
        title = f"{c} variance{suffix}"
        shown.append(_panel(axes[3 + k], var[..., k], extent, "magma", 0.0, top, title))
    return shown


def _labels(fmap: MagneticFieldMap) -> list[str]:
    units = "sensor units" if fmap.units == "unknown" else fmap.units
    return [units] * 3 + [f"({units})^2"] * 3


def render_field_map(
    fmap: MagneticFieldMap, path: str | os.PathLike, slices: int = 4, title: str | None = None
) -> Path:
    """Draws the map to a PNG of :func:`picture_size` (written atomically); returns the path.
    Means share a colour range per component across the slices of a 3-D map; variances run
    from 0 to the prior variance."""
    if not isinstance(fmap, MagneticFieldMap):
        raise ValueError(f"expected a MagneticFieldMap, got {type(fmap).__name__}")
    width, height = picture_size(fmap, slices)
    fig = new_figure(figsize=(width / DPI, height / DPI), dpi=DPI)
    top = 1.0 - 45.0 / height  # room for the title (a fixed layout: constrained is slow)
    fig.subplots_adjust(left=0.04, right=0.97, bottom=0.2 / (height / DPI), top=top)
    fig.subplots_adjust(wspace=0.3, hspace=0.35)
    lo, hi = fmap.lower, fmap.upper
    extent = [lo[0], hi[0], lo[1], hi[1]]
    means = fmap.mean.reshape(-1, 3)
    ranges = [(float(means[:, k].min()), float(means[:, k].max())) for k in range(3)]
    if fmap.dimension == 2:
        axes = fig.subplots(2, 3).ravel()
        shown = _draw_row(axes, fmap, fmap.mean, fmap.variance, extent, ranges, "")
        for image, ax, label in zip(shown, axes, _labels(fmap), strict=True):
            _colour_bar(fig, image, ax, label)
        at = "" if fmap.height is None else f" at {fmap.height:.2f} m"
        for ax in axes[3:]:
            ax.set_xlabel("x (m)", fontsize=8)
        for ax in axes[::3]:
            ax.set_ylabel("y (m)", fontsize=8)
    else:
        layers = slice_indices(fmap, slices)
        axes = np.atleast_2d(fig.subplots(len(layers), 6))
        for row, k in zip(axes, layers, strict=True):
            z = fmap.origin[2] + (k + 0.5) * fmap.resolution
            suffix = f", z {z:.2f} m"
            shown = _draw_row(row, fmap, fmap.mean[k], fmap.variance[k], extent, ranges, suffix)
            row[0].set_ylabel("y (m)", fontsize=8)
            for image, ax, label in zip(shown, row, _labels(fmap), strict=True):
                _colour_bar(fig, image, ax, label)
        for ax in axes[-1]:
            ax.set_xlabel("x (m)", fontsize=8)
        at = f", {len(layers)} of {fmap.mean.shape[0]} voxel layers"
    fig.suptitle(title or f"magnetic field map, {fmap.resolution:g} m cells{at}", fontsize=11)
    return atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=DPI))
