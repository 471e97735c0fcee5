# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What ``kiseki terrain planes`` writes: the picture of a cloud's planes (a top view x-y and a
side view x-z; removed points grey or one colour per plane, kept points coloured by height)
and the planes' CSV (``plane,a,b,c,d,inliers``: a x + b y + c z + d = 0, unit normal)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki._support.atomic import atomic_write
from kiseki.terrain.cloud_planes import Cloud, CloudPlanes

__all__ = ["PLANES_COLUMNS", "planes_summary", "render_cloud_planes", "write_planes_csv"]

PLANES_COLUMNS = ("plane", "a", "b", "c", "d", "inliers")
DRAWN = 60_000  # points drawn per view at most (a seeded subset of larger clouds)


def write_planes_csv(result: CloudPlanes, path: str | os.PathLike) -> None:
    text = ",".join(PLANES_COLUMNS) + "\n"
    for k, (plane, n) in enumerate(zip(result.planes, result.inliers, strict=True)):
        text += f"{k}," + ",".join(f"{v:.6f}" for v in plane) + f",{int(n)}\n"
    atomic_write(path, lambda tmp: Path(tmp).write_text(text))


def planes_summary(cloud: Cloud, result: CloudPlanes) -> list[str]:
    """The lines printed by the command: one per plane, then the share kept."""
    n = len(cloud.points)
    lines = []
    for k, (p, m) in enumerate(zip(result.planes, result.inliers, strict=True)):
        lines.append(
            f"plane {k}: normal ({p[0]:+.3f}, {p[1]:+.3f}, {p[2]:+.3f}), offset {p[3]:+.3f} m, "
            f"{int(m)} points ({100 * m / n:.1f} %)"
        )
    if result.method == "hough":
        origin = ", ".join(f"{v:g}" for v in cloud.origin)
        lines.append(
            f"hough: {result.lines} lines over the tilt scans of an S-DEM of "
            f"{result.extra.get('sdem_cells', 0)} cells (sensor at ({origin}))"
        )
    kept = int(np.sum(~result.removed))
    lines.append(
        f"{cloud.path}: {n} points ({cloud.dropped} non-finite dropped), "
        f"{len(result.planes) if result.method == 'pcl' else result.lines} "
        f"{'planes' if result.method == 'pcl' else 'lines'} ({result.method}, fitted on "
        f"{result.fitted} {'points' if result.method == 'pcl' else 'cells'}); "
        f"kept {kept} ({100 * kept / n:.1f} %)"
    )
    return lines


def render_cloud_planes(
    cloud: Cloud, result: CloudPlanes, path: str | os.PathLike, seed: int = 0
) -> None:
    # here, not at the top: matplotlib takes a second to load, and only drawing needs it
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is chosen, as above

    pts, label = cloud.points, result.label
    if len(pts) > DRAWN:
        pick = np.sort(np.random.default_rng(seed).choice(len(pts), DRAWN, replace=False))
        pts, label = pts[pick], label[pick]
    fig, axes = plt.subplots(1, 2, figsize=(13, 6), dpi=110)
    colours = plt.get_cmap("tab10")
    views = (((0, 1), "x-y (top view if z is up)"), ((0, 2), "x-z (side view)"))
    for ax, ((i, j), name) in zip(axes, views, strict=True):
        gone = label >= 0
        if result.method == "pcl" and len(result.planes):
            for k in range(len(result.planes)):
                on = label == k
                ax.scatter(pts[on, i], pts[on, j], s=0.6, color=colours(k % 10), alpha=0.6,
                           linewidths=0, label=f"plane {k} ({int(result.inliers[k])})")  # fmt: skip
        else:
            ax.scatter(pts[gone, i], pts[gone, j], s=0.6, color="0.7", linewidths=0,
                       label="removed")  # fmt: skip
        keep = ~gone
        ax.scatter(pts[keep, i], pts[keep, j], s=0.8, c=pts[keep, 2], cmap="viridis",
                   linewidths=0, label="kept (colour: z)")  # fmt: skip
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("xyz"[i] + " (m)")
        ax.set_ylabel("xyz"[j] + " (m)")
        ax.set_title(name)
    axes[0].legend(loc="best", markerscale=8, fontsize=7)
    fig.suptitle(
        f"{Path(cloud.path).name}: {result.method}, kept {100 * result.kept_share:.1f} % "
        f"of {len(cloud.points)} points"
    )
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)
