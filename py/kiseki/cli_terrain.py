# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki terrain``: the rubble paper's 3-D localization and mapping (paper 003)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._interrupt import interruptible

__all__ = ["terrain_app"]

terrain_app = typer.Typer(
    no_args_is_help=True,
    help="3-D localization and mapping in rubble: sphere elevation maps, plane removal, "
    "correlation search, OctoMap global maps.",
)
console = Console(soft_wrap=True)
TRAJECTORY_COLUMNS = ("move", "x_true", "y_true", "z_true", "x_est", "y_est", "z_est")


def _destination(out: Path) -> None:
    if out.exists() and not out.is_dir():
        raise ValueError(f"-o {out}: exists and is not a folder")
    if (out / "trajectory.csv").exists():
        raise ValueError(f"-o {out}: already holds a run (trajectory.csv); choose another folder")
    out.mkdir(parents=True, exist_ok=True)


@terrain_app.command("run")
@interruptible()
def terrain_run(
    world: Path = typer.Argument(
        ..., help="A scene YAML with a tilting_laser and a route, or an OctoMap .bt building."
    ),
    moves: int = typer.Option(..., "--moves", help="Moves after the first stop (1..200)."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder to write the run to."),
    seed: int = typer.Option(0, help="Seed of the laser's noise, the gyro and PCL's RANSAC."),
    step: float = typer.Option(0.35, help="Metres between stops (0.02..0.6)."),
    removal: str = typer.Option("hough", help="Plane removal: hough (the paper's), pcl, none."),
    search: str = typer.Option(
        "coarse-to-fine", help="exhaustive (the paper's 56,916 candidates) or coarse-to-fine."
    ),
) -> None:
    """Moves a robot through WORLD stopping every --step metres; at each stop a tilting-laser
    sweep becomes an S-DEM, the motion since the last stop is found by the correlation search,
    and the sweep is merged into an OctoMap at the estimated pose. Writes OUT/sdem_KKK.pcd (each
    stop's levelled S-DEM points after plane removal, sensor frame), OUT/trajectory.csv
    (move,x_true,y_true,z_true,x_est,y_est,z_est: the sensor's position, metres),
    OUT/global_map.bt (octovis opens it), OUT/trajectory.png and OUT/config.yaml.

    Example: kiseki terrain run data/worlds/rubble_a.yaml --moves 10 -o rubble-run"""
    import yaml
    from tqdm import tqdm

    from kiseki import _core
    from kiseki._atomic import atomic_write
    from kiseki.core import check_seed
    from kiseki.sim.terrain_moves import terrain_stops
    from kiseki.terrain.mapper import MapperConfig, SdemMapper

    seed = check_seed(seed, "--seed")
    if not world.exists():
        raise ValueError(f"WORLD {world}: no such file")
    config = MapperConfig(removal=removal, search=search, seed=seed)  # checks both names
    _destination(output)
    stops = terrain_stops(world, moves, seed, step)
    mapper = SdemMapper(config, start=stops[0].sensor[:3, 3])
    rows = []
    for k, stop in enumerate(tqdm(stops, desc="stops", unit="sweep")):
        pose = mapper.add(stop.ranges, stop.gyro_rpy)
        points, _ = mapper.sweeps[-1].kept.to_points()
        _core.write_pcd(str(output / f"sdem_{k:03d}.pcd"), points)
        rows.append([k, *stop.sensor[:3, 3], *pose[:3, 3]])
    table = np.asarray(rows)
    text = ",".join(TRAJECTORY_COLUMNS) + "\n"
    text += "".join(f"{int(r[0])}," + ",".join(f"{v:.4f}" for v in r[1:]) + "\n" for r in table)
    atomic_write(output / "trajectory.csv", lambda tmp: Path(tmp).write_text(text))
    mapper.global_map.write_binary(str(output / "global_map.bt"))
    doc = {"world": str(world), "moves": moves, "seed": seed, "step": step, **config.to_dict()}
    doc["hough"], doc["pcl"] = vars(config.hough), vars(config.pcl)
    atomic_write(output / "config.yaml", lambda tmp: Path(tmp).write_text(yaml.safe_dump(doc)))
    from kiseki.terrain.render import render_run

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


@terrain_app.command("planes")
@interruptible()
def terrain_planes(
    cloud: Path = typer.Argument(
        ..., help="A PCD file, or a text file of 'x y z' lines (also .bz2 compressed)."
    ),
    output: Path = typer.Option(..., "-o", "--output", help="The picture to write (PNG)."),
    csv: Path | None = typer.Option(None, "--csv", help="Also write the planes as CSV."),
    method: str = typer.Option("pcl", help="pcl (3-D planes) or hough (lines per tilt scan)."),
    seed: int = typer.Option(0, help="Seed of the subset and PCL's RANSAC."),
    max_points: int = typer.Option(
        20_000, "--max-points", help="PCL fits planes on a seeded subset of this many points."
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
    from kiseki.terrain.cloud_picture import planes_summary, render_cloud_planes, write_planes_csv
    from kiseki.terrain.cloud_planes import CLOUD_METHODS, cloud_planes, read_cloud

    if method not in CLOUD_METHODS:
        raise ValueError(f"--method must be one of {CLOUD_METHODS}, got {method!r}")
    if output.suffix.lower() != ".png":
        raise ValueError(f"-o {output}: expected a .png file")
    for name, path in (("-o", output), ("--csv", csv)):
        if path is not None and (path.is_dir() or not path.parent.is_dir()):
            raise ValueError(f"{name} {path}: is a folder or its folder does not exist")
    points = read_cloud(cloud, origin)
    result = cloud_planes(points, method, seed, max_points)
    for line in planes_summary(points, result):
        console.print(line, highlight=False)
    render_cloud_planes(points, result, output, seed)
    if csv is not None:
        write_planes_csv(result, csv)
