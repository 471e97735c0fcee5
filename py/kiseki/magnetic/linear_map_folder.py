# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A linear magnetic map on disk: one folder holding

* ``linear_map.yaml``: ``kind: linear_magnetic_map``, ``format_version``, ``node_spacing`` (m),
  ``nodes``, ``first_node_s`` (m), ``path_id`` (SHA-1 of the taught route's waypoints, see
  :func:`kiseki.magnetic.linear_map.path_identity`), ``units`` (G), ``sensor_frame``,
  ``geometric_window`` (range m, angle deg of the g windows), ``travel_distance`` (where s
  came from), ``provenance``, ``kiseki_version`` and ``files``;
* ``nodes.npz``: the float64 arrays ``s``, ``field`` (n, 3), ``m_theta``, ``heading``, ``g``
  (n, 2, NaN: no obstacle), ``position`` (n, 2, NaN: unknown) and int64 ``count``.

Both files are written by :func:`kiseki._support.atomic.atomic_write_all` (the arrays before the
YAML). A folder of the GP magnetic field maps (:mod:`kiseki.magnetic.map_folder`,
``magnetic_map.yaml``) is refused here, and that module refuses this kind.
"""

from __future__ import annotations

import zipfile
import zlib
from pathlib import Path
from typing import Literal

import numpy as np
import yaml
from pydantic import Field

from kiseki import __version__
from kiseki._support.atomic import atomic_write_all
from kiseki._support.inputs import GIB, YAML_LIMIT, check_input, check_npz, read_input_text
from kiseki._support.schema import (
    MAGNITUDE_LIMIT,
    FileModel,
    FiniteFloat,
    PositiveFloat,
    PositiveInt,
    parse,
)
from kiseki._support.yaml import read_yaml_file, safe_load_12
from kiseki.errors import KisekiError, MapFormatError
from kiseki.magnetic.linear_map import MAX_NODES, LinearMagneticMap

__all__ = [
    "KIND",
    "MAP_FILE",
    "MAX_NODES_BYTES",
    "OtherPathError",
    "load_linear_map",
    "save_linear_map",
]

MAP_FILE = "linear_map.yaml"
NODES_FILE = "nodes.npz"
MAX_NODES_BYTES = 2 * GIB  # the nodes' arrays: 10 million nodes (the YAML's limit) hold 1.1 GB
KIND = "linear_magnetic_map"
FORMAT_VERSION = 1
GP_MAP_FILE = "magnetic_map.yaml"  # kiseki.magnetic.map_folder.MAP_FILE
SENSOR_FRAME = "x forward, y right, z down"
TRAVEL_DISTANCE = "odometry of the teaching run (thesis sec. 4.3.1)"
_ARRAYS = ("s", "field", "m_theta", "heading", "g", "position", "count")


class OtherPathError(KisekiError, ValueError):
    """A linear magnetic map loaded for a path other than the one it was taught on."""


class _Window(FileModel):
    range_m: PositiveFloat
    angle_deg: PositiveFloat = Field(le=180.0)


class LinearMapDoc(FileModel):
    """``linear_map.yaml``."""

    kind: Literal["linear_magnetic_map"]
    format_version: Literal[1]
    node_spacing: PositiveFloat
    nodes: PositiveInt = Field(le=MAX_NODES)
    first_node_s: FiniteFloat
    path_id: str = Field(pattern=r"^[0-9a-f]{40}$")
    units: Literal["G"]
    sensor_frame: Literal["x forward, y right, z down"]
    geometric_window: _Window
    travel_distance: str
    provenance: dict[str, str] = {}
    kiseki_version: str
    files: dict[Literal["nodes"], str]


def _is_kind(folder: Path, name: str, kind: str) -> bool:

    try:
        doc = safe_load_12(read_input_text(folder / name, "YAML files", YAML_LIMIT))
    except (OSError, ValueError, yaml.YAMLError):  # UnicodeDecodeError is a ValueError
        return False
    return isinstance(doc, dict) and doc.get("kind") == kind


def _gp_refusal(folder: Path) -> MapFormatError:
    return MapFormatError(
        f"{folder}: a GP magnetic map ({GP_MAP_FILE}, kind magnetic_field_map), not a linear one"
    )


def save_linear_map(lmap: LinearMagneticMap, folder) -> Path:
    """Writes ``lmap`` to ``folder`` (created if absent; its parent must exist). A folder
    holding another linear map is overwritten; a GP map folder or any other non-empty folder
    is refused."""

    if not isinstance(lmap, LinearMagneticMap):
        raise ValueError(f"expected a LinearMagneticMap, got {type(lmap).__name__}")
    folder = Path(folder)
    if not folder.parent.is_dir():
        raise FileNotFoundError(f"{folder}: folder {folder.parent} does not exist")
    if folder.exists():
        if not folder.is_dir():
            raise FileExistsError(f"{folder} exists and is not a folder: refusing to replace it")
        if (folder / GP_MAP_FILE).exists():
            raise _gp_refusal(folder)
        if any(folder.iterdir()) and not _is_kind(folder, MAP_FILE, KIND):
            raise FileExistsError(
                f"{folder} exists and is not a linear magnetic map folder: refusing to write in it"
            )
    folder.mkdir(exist_ok=True)
    doc = {
        "kind": KIND,
        "format_version": FORMAT_VERSION,
        "node_spacing": lmap.spacing,
        "nodes": len(lmap),
        "first_node_s": float(lmap.s[0]),
        "path_id": lmap.path_id,
        "units": "G",
        "sensor_frame": SENSOR_FRAME,
        "geometric_window": {
            "range_m": float(lmap.window[0]),
            "angle_deg": round(float(np.degrees(lmap.window[1])), 9),
        },
        "travel_distance": TRAVEL_DISTANCE,
        "provenance": {str(k): str(v) for k, v in lmap.provenance.items()},
        "kiseki_version": __version__,
        "files": {"nodes": NODES_FILE},
    }
    arrays = {name: getattr(lmap, name) for name in _ARRAYS}
    text = yaml.safe_dump(doc, sort_keys=False)

    def write_yaml(tmp: str) -> None:
        Path(tmp).write_text(text, encoding="utf-8")

    def write_nodes(tmp: str) -> None:
        with open(tmp, "wb") as out:
            np.savez(out, **arrays)

    atomic_write_all([(folder / NODES_FILE, write_nodes), (folder / MAP_FILE, write_yaml)])
    return folder


def _read_nodes(path: Path, n: int) -> dict[str, np.ndarray]:
    check_npz(path, "linear magnetic map nodes", MAX_NODES_BYTES, MapFormatError)
    try:
        with np.load(path, allow_pickle=False) as npz:
            found = {k: npz[k] for k in npz.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as err:
        raise MapFormatError(f"{path}: not a readable .npz file ({err})") from None
    shapes = {"field": (n, 3), "g": (n, 2), "position": (n, 2)}
    for name in _ARRAYS:
        if name not in found:
            raise MapFormatError(f"{path}: missing array '{name}'")
        a, shape = found[name], shapes.get(name, (n,))
        if a.shape != shape or a.dtype.kind not in "fiu":
            raise MapFormatError(f"{path}: '{name}' is {a.dtype} {a.shape}, expected {shape}")
        nan_ok = name in ("g", "position")
        if (np.isinf(a) if nan_ok else ~np.isfinite(a)).any():
            raise MapFormatError(f"{path}: '{name}' holds NaN or infinity")
        if (np.abs(a) > MAGNITUDE_LIMIT).any():
            raise MapFormatError(
                f"{path}: '{name}' holds {np.nanmax(np.abs(a)):g}, beyond +-{MAGNITUDE_LIMIT:g}"
            )
    if (found["count"] < 0).any():
        raise MapFormatError(f"{path}: 'count' holds negative numbers")
    return found


def load_linear_map(folder, path_id: str | None = None) -> LinearMagneticMap:
    """Reads a folder written by :func:`save_linear_map`. With ``path_id``, a map of another
    path raises :class:`OtherPathError` naming both identities. A GP magnetic map folder, a
    malformed YAML or arrays that disagree with it raise MapFormatError (SchemaError for the
    YAML's fields) naming the file; an absent folder FileNotFoundError."""

    folder = Path(folder)
    if not folder.exists():
        raise FileNotFoundError(f"{folder}: no such linear magnetic map folder")
    meta = folder / MAP_FILE
    check_input(meta, error=MapFormatError)
    if not folder.is_dir() or not meta.is_file():
        if folder.is_dir() and (folder / GP_MAP_FILE).is_file():
            raise _gp_refusal(folder)
        raise MapFormatError(f"{folder}: not a linear magnetic map (no {MAP_FILE})")
    try:
        doc = read_yaml_file(meta, "linear magnetic map description")
    except ValueError as err:
        raise MapFormatError(str(err)) from None
    if isinstance(doc, dict) and doc.get("kind") == "magnetic_field_map":
        raise _gp_refusal(folder)
    model = parse(LinearMapDoc, doc, meta)
    if path_id is not None and model.path_id != path_id:
        raise OtherPathError(
            f"{folder}: a linear magnetic map of path {model.path_id}, not of this path {path_id}"
        )
    name = model.files["nodes"]
    check_input(folder / name, error=MapFormatError)
    if Path(name).name != name or not (folder / name).is_file():
        raise MapFormatError(f"{meta}: files: nodes must name a file in the folder, got {name!r}")
    arrays = _read_nodes(folder / name, model.nodes)
    expected = model.first_node_s + np.arange(model.nodes) * model.node_spacing
    if not np.allclose(arrays["s"], expected, rtol=0, atol=1e-9 * max(1.0, abs(expected).max())):
        raise MapFormatError(f"{folder / name}: 's' disagrees with first_node_s and node_spacing")
    return LinearMagneticMap(
        spacing=model.node_spacing,
        path_id=model.path_id,
        s=arrays["s"].astype(np.float64),
        field=arrays["field"].astype(np.float64),
        m_theta=arrays["m_theta"].astype(np.float64),
        heading=arrays["heading"].astype(np.float64),
        g=arrays["g"].astype(np.float64),
        count=arrays["count"].astype(np.int64),
        position=arrays["position"].astype(np.float64),
        window=(model.geometric_window.range_m, np.radians(model.geometric_window.angle_deg)),
        provenance=dict(model.provenance),
    )
