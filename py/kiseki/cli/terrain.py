# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki terrain``: the rubble paper's 3-D localization and mapping (paper 003)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer
import yaml
from rich.console import Console
from tqdm import tqdm

from kiseki import _core
from kiseki._support.atomic import atomic_write
from kiseki._support.guard import Folder, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import Count, Metres, Seed, refuse_given
from kiseki._support.replaced_files import refuse_replacing
from kiseki.cli._defaults import default_of
from kiseki.sim.terrain_moves import terrain_stops
from kiseki.terrain.cloud_picture import planes_summary, render_cloud_planes, write_planes_csv
from kiseki.terrain.cloud_planes import CLOUD_METHODS, cloud_planes, read_cloud
from kiseki.terrain.mapper import MapperConfig, SdemMapper
from kiseki.terrain.render import render_run

__all__ = ["app"]

app = typer.Typer(
    no_args_is_help=True,
    help="3-D localization and mapping in rubble: sphere elevation maps, plane removal, "
    "correlation search, OctoMap global maps.",
)
console = Console(soft_wrap=True)
TRAJECTORY_COLUMNS = ("move", "x_true", "y_true", "z_true", "x_est", "y_est", "z_est")
# what kiseki terrain run writes in its -o folder (kiseki._support.guard)
_RUN_FILES = Folder(
    "output", ("sdem_*.pcd", "trajectory.csv", "global_map.bt", "trajectory.png", "config.yaml")
)


def _destination(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise ValueError(f"-o {out}: exists and is not a folder")
    if (out / "trajectory.csv").exists():
        raise ValueError(f"-o {out}: already holds a run (trajectory.csv); choose another folder")
    # a folder of the user's own files (-o . holding a config.yaml) keeps them
    remedy = "choose another folder (an unfinished run leaves its sdem_*.pcd: remove them)"
    refuse_replacing(out, _RUN_FILES.writes, "-o", remedy)
    out.mkdir(parents=True, exist_ok=True)


@app.command("run")
@guarded(inputs=("world",), output_folders=(_RUN_FILES,))
@interruptible()
def terrain_run(
    world: Path = typer.Argument(
        ..., help="A scene YAML with a tilting_laser and a route, or an OctoMap .bt building."
    ),
    # kiseki.sim.terrain_moves' limits: a sweep and a correlation search per stop, and steps
    # the search reaches (it covers 0.7 m)
    moves: int = typer.Option(
        ..., "--moves", parser=Count("--moves", 1, 200), help="Moves after the first stop."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Folder to write the run to."),
    seed: int = typer.Option(
        0, parser=Seed(), help="Seed of the laser's noise, the gyro and PCL's RANSAC."
    ),
    step: float = typer.Option(
        0.35, parser=Metres("--step", 0.02, 0.6), help="Metres between stops."
    ),
    removal: str = typer.Option(
        default_of(MapperConfig, "removal"), help="Plane removal: hough (the paper's), pcl, none."
    ),
    search: str = typer.Option(
        default_of(MapperConfig, "search"),
        help="exhaustive (the paper's 56,916 candidates) or coarse-to-fine.",
    ),
    cost: str = typer.Option(
        default_of(MapperConfig, "cost"),
        help="Eq. 4 as printed (sum) or kiseki's variant (mean: over the summed weights).",
    ),
) -> None:
    """Moves a robot through WORLD stopping every --step metres; at each stop a tilting-laser
    sweep becomes an S-DEM, the motion since the last stop is found by the correlation search,
    and the sweep is merged into an OctoMap at the estimated pose. Writes OUT/sdem_KKK.pcd (each
    stop's levelled S-DEM points after plane removal, sensor frame), OUT/trajectory.csv
    (move,x_true,y_true,z_true,x_est,y_est,z_est: the sensor's position, metres),
    OUT/global_map.bt (octovis opens it), OUT/trajectory.png and OUT/config.yaml.

    Example: kiseki terrain run data/worlds/rubble_a.yaml --moves 10 -o rubble-run"""
    if not world.exists():
        raise ValueError(f"WORLD {world}: no such file")
    config = MapperConfig(removal=removal, search=search, cost=cost, seed=seed)  # checks the names
    _destination(output)
    stops = terrain_stops(world, moves, seed, step)
    mapper = SdemMapper(config, start=stops[0].sensor[:3, 3])
    rows = []
    for k, stop in enumerate(tqdm(stops, desc="stops", unit="sweep")):
        try:
            pose = mapper.add(stop.ranges, stop.gyro_rpy)
        except ValueError as err:  # "sweep 3: no candidate shares ...": of this world's run
            raise ValueError(f"{world}: {err}") from None
        points, _ = mapper.sweeps[-1].kept.to_points()
        atomic_write(output / f"sdem_{k:03d}.pcd", lambda tmp, p=points: _core.write_pcd(tmp, p))
        rows.append([k, *stop.sensor[:3, 3], *pose[:3, 3]])
    table = np.asarray(rows)
    text = ",".join(TRAJECTORY_COLUMNS) + "\n"
    text += "".join(f"{int(r[0])}," + ",".join(f"{v:.4f}" for v in r[1:]) + "\n" for r in table)
    atomic_write(output / "trajectory.csv", lambda tmp: Path(tmp).write_text(text))
    atomic_write(output / "global_map.bt", mapper.global_map.write_binary)
    doc = {"world": str(world), "moves": moves, "seed": seed, "step": step, **config.to_dict()}
    doc["hough"], doc["pcl"] = vars(config.hough), vars(config.pcl)
    atomic_write(output / "config.yaml", lambda tmp: Path(tmp).write_text(yaml.safe_dump(doc)))

    render_run(table, mapper.global_map, output / "trajectory.png", title=world.name)
    err = np.linalg.norm(table[:, 4:7] - table[:, 1:4], axis=1)
    travelled = float(np.sum(np.linalg.norm(np.diff(table[:, 1:4], axis=0), axis=1)))
    console.print(
        f"{output}: {len(stops)} stops over {travelled:.2f} m; final error {err[-1]:.3f} m "
        f"({100 * err[-1] / max(travelled, 1e-9):.1f} % of the distance), "
        f"largest {err.max():.3f} m; "
        f"global map {mapper.global_map.occupied_leaves} occupied voxels of "
        f"{mapper.global_map.resolution:g} m"
    )


@app.command("planes")
@guarded(inputs=("cloud",), outputs=("output", "csv"))
@interruptible()
def terrain_planes(
    ctx: typer.Context,
    cloud: Path = typer.Argument(
        ..., help="A PCD file, or a text file of 'x y z' lines (also .bz2 compressed)."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="The picture to write (PNG)."),
    csv: Path | None = typer.Option(None, "--csv", help="Also write the planes as CSV."),
    method: str = typer.Option("pcl", help="pcl (3-D planes) or hough (lines per tilt scan)."),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the subset and PCL's RANSAC."),
    # cloud_planes' least (fewer points find no plane reliably); 10^7 points are 240 MB of xyz
    max_points: int = typer.Option(
        20_000,
        "--max-points",
        parser=Count("--max-points", 100, 10_000_000),
        help="PCL fits planes on a seeded subset of this many points (pcl only).",
    ),
    origin: str | None = typer.Option(
        None,
        "--origin",
        help="The sensor's position x,y,z (m) for hough (default: PCD's "
        "VIEWPOINT, 0,0,0 for text).",
    ),
) -> None:
    """Finds and removes the planes (floor, walls, tables) of a 3-D cloud and prints each plane
    (normal, offset, points) and the share of points kept. OUT.png shows a top and a side view:
    each plane's points in its own pale colour, kept points coloured by height. --csv writes
    plane,a,b,c,d,inliers (a x + b y + c z + d = 0, unit normal). Hough works on an S-DEM centred
    on the sensor: PCD's VIEWPOINT, (0, 0, 0) for text files.

    Example: kiseki terrain planes scan.dat.bz2 -o planes.png --csv planes.csv"""
    if method not in CLOUD_METHODS:
        raise ValueError(f"--method must be one of {CLOUD_METHODS}, got {method!r}")
    if output.suffix.lower() != ".png":
        raise ValueError(f"-o {output}: expected a .png file")
    if method == "pcl":  # RANSAC on the points: no sensor position
        refuse_given(ctx, ["origin"], "to --method pcl (hough's S-DEM is centred on it)")
    else:  # the S-DEM's cells, not a subset of points
        refuse_given(ctx, ["max_points"], f"to --method {method} (pcl's subset)")
    points = read_cloud(cloud, origin)
    result = cloud_planes(points, method, seed, max_points)
    for line in planes_summary(points, result):
        console.print(line, highlight=False)
    render_cloud_planes(points, result, output, seed)
    if csv is not None:
        write_planes_csv(result, csv)
