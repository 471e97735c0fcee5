# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A magnetic field map on disk: one folder that declares its kind and dimension.

``magnetic_map.yaml``: ``kind: magnetic_field_map``, ``format_version``, ``dimension``,
``origin`` (world coordinates of the lower corner of cell 0), ``resolution`` (m), ``shape``
(cells along x, y[, z]), ``units`` (of the mean; the variance is in units squared),
``frame: world``, ``prior_mean``, ``prior_variance``, ``kernel`` (sigma_f, length_scale,
sigma_n; or one such entry per component), ``height`` (2-D), ``provenance`` (the data it was
fitted from and how), ``kiseki_version`` and ``files``.

2-D maps: one image per layer, ``mx_mean.png`` ... ``mz_variance.png``, like the ROS map format:
row 0 of the image is the top of the map (the highest y), and each image is a 16-bit grey PNG
whose pixel p stands for ``offset + scale * p`` (``scale`` and ``offset`` per layer in the
YAML; scale = range / 65535, so the rounding is at most range / 131070, about 0.5 nT over a
60 uT range, far below a magnetometer's noise). Any image viewer or GIS tool opens them, and
OpenCV writes them; a 32-bit float TIFF would keep the values but most viewers show it black
or refuse it. The exact float64 values are in ``layers.npz`` (one array per layer, shaped
(ny, nx), row 0 at the LOWEST y, plus ``origin`` and ``resolution``), which loading reads.

3-D maps: ``voxels.npz`` with ``mean`` and ``variance`` (nz, ny, nx, 3), ``origin`` and
``resolution``; the layout is OctoMap's: voxel (i, j, k) has its centre at ``origin + ((i, j,
k) + 0.5) * resolution`` with the origin a multiple of the resolution, which is the centre of
OctoMap key ``origin / resolution + 32768 + (i, j, k)`` (the YAML's ``octomap_key_origin``).

``training.npz`` (X (n, d), Y (n, 3)), when the map keeps its measurements, lets predictions
re-evaluate the GP exactly; ``predictor.npz`` (a curl-free map's) holds the fitted GP's factor
(:func:`kiseki.magnetic.map_gp.predictor_state`), so that they need no refit. A folder is
written under a temporary name and renamed into place.

The files alone: :func:`write_map_folder` writes a map's fields, :func:`read_map_folder` reads
them back checked; the map type (:mod:`kiseki.magnetic.field_map`) builds on this module.
"""

from __future__ import annotations

import math
import os
import shutil
import struct
import tempfile
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from kiseki._support.atomic import record_written
from kiseki._support.inputs import GIB, YAML_LIMIT, check_input, check_npz, read_input_text
from kiseki._support.real_numbers import check_number
from kiseki._support.replaced_files import first_of
from kiseki._support.schema import MAGNITUDE_LIMIT
from kiseki._support.yaml import read_yaml_file, safe_load_12
from kiseki.errors import MapFormatError
from kiseki.io.ros_map import read_image, write_image
from kiseki.magnetic.map_doc import (
    COMPONENTS,
    KIND,
    MagneticMapDoc,
    describe_map,
    read_map_doc,
)

__all__ = [
    "COMPONENTS",
    "MAP_FILE",
    "MAP_FOLDER_FILES",
    "MAX_FILE_BYTES",
    "KIND",
    "MapFolderContents",
    "check_map_destination",
    "read_map_folder",
    "write_map_folder",
]

MAP_FILE = "magnetic_map.yaml"
LINEAR_MAP_FILE = "linear_map.yaml"  # kiseki.magnetic.linear_map_folder.MAP_FILE: refused here
LAYERS = tuple(f"{c}_{q}" for q in ("mean", "variance") for c in COMPONENTS)
# every file write_map_folder writes (2-D or 3-D, with or without training data): a map folder
# is replaced whole, so one holding anything else is refused
MAP_FOLDER_FILES = frozenset(
    {MAP_FILE, "layers.npz", "voxels.npz", "training.npz", "predictor.npz"}
    | {f"{name}.png" for name in LAYERS}
)
MAX_FILE_BYTES = 2 * GIB
"""Each file of a map folder, and the arrays of each ``.npz``, hold at most this: a map of
MAX_CELLS cells keeps its mean and variance in 960 MB, 10 million training points in 480 MB."""
_PNG = b"\x89PNG\r\n\x1a\n"
_LEVELS = 65535


def _is_map_folder(path: Path) -> bool:
    try:
        doc = safe_load_12(read_input_text(path / MAP_FILE, "YAML files", YAML_LIMIT))
    except (OSError, ValueError, yaml.YAMLError):  # UnicodeDecodeError is a ValueError
        return False
    return isinstance(doc, dict) and doc.get("kind") == KIND


def check_map_destination(folder, label: str = "") -> Path:
    """Checks before any work that a map can be written to `folder`: its parent exists and is
    writable, and the folder is absent, empty, or a magnetic field map holding only a map's own
    files (it is replaced whole: a user's file in it would go with it). `label` (``-o``) starts
    that refusal. Returns the folder as a Path."""
    folder = Path(folder)
    parent = folder.parent if str(folder.parent) else Path(".")
    if not parent.is_dir():
        raise FileNotFoundError(f"{folder}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PermissionError(f"{folder}: folder {parent} is not writable")
    if folder.exists() or folder.is_symlink():
        if not folder.is_dir() or folder.is_symlink():
            raise FileExistsError(f"{folder} exists and is not a folder: refusing to replace it")
        if any(folder.iterdir()) and not _is_map_folder(folder):
            raise FileExistsError(
                f"{folder} exists and is not a magnetic field map folder: refusing to replace it"
            )
        foreign = sorted(p.name for p in folder.iterdir() if p.name not in MAP_FOLDER_FILES)
        if foreign:
            raise FileExistsError(
                f"{label + ' ' if label else ''}{folder} holds {first_of(foreign)}, which is not "
                "part of a magnetic field map: the map folder is replaced whole; move "
                f"{'them' if len(foreign) > 1 else 'it'} out, or give a new folder"
            )
    return folder


def _write_layers_2d(fmap, tmp: Path) -> dict:

    arrays = {"origin": fmap.origin, "resolution": np.float64(fmap.resolution)}
    images = {}
    for name in LAYERS:
        component, quantity = name.split("_")
        layer = getattr(fmap, quantity)[..., COMPONENTS.index(component)]
        arrays[name] = layer
        lo, hi = float(layer.min()), float(layer.max())
        scale = (hi - lo) / _LEVELS
        pixels = np.zeros(layer.shape) if scale == 0 else np.rint((layer - lo) / scale)
        image = np.clip(pixels, 0, _LEVELS).astype(np.uint16)[::-1]  # row 0 = highest y
        write_image(tmp / f"{name}.png", np.ascontiguousarray(image))  # checked: a full disk
        images[name] = {"image": f"{name}.png", "scale": scale, "offset": lo}
    np.savez(tmp / "layers.npz", **arrays)
    return {"layers": images, "arrays": "layers.npz"}


def write_map_folder(fmap, folder) -> Path:
    """Writes the fields of `fmap` (a :class:`~kiseki.magnetic.field_map.MagneticFieldMap`,
    checked by :func:`~kiseki.magnetic.field_map.save_map_folder`) to `folder` (see the module
    text): a temporary folder beside it, renamed into place; an existing map folder (or an empty
    folder) is replaced, anything else refused."""
    folder = check_map_destination(folder)
    tmp = Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}."))
    try:
        if fmap.dimension == 2:
            files = _write_layers_2d(fmap, tmp)
        else:
            np.savez(
                tmp / "voxels.npz",
                mean=fmap.mean,
                variance=fmap.variance,
                origin=fmap.origin,
                resolution=np.float64(fmap.resolution),
            )
            files = {"arrays": "voxels.npz"}
        if fmap.training is not None:
            np.savez(tmp / "training.npz", X=fmap.training.inputs, Y=fmap.training.outputs)
            files["training"] = "training.npz"
            if fmap.training.predictor is not None:
                np.savez(tmp / "predictor.npz", **fmap.training.predictor)
                files["predictor"] = "predictor.npz"
        text = yaml.safe_dump(describe_map(fmap, files), sort_keys=False, default_flow_style=None)
        (tmp / MAP_FILE).write_text(text, encoding="utf-8")
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o777 & ~mask)
        _swap_into_place(tmp, folder)
        record_written(folder)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return folder


def _swap_into_place(tmp: Path, folder: Path) -> None:
    if not folder.exists() or not any(folder.iterdir()):
        os.replace(tmp, folder)  # an empty folder is replaced in one step
        return
    old = Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}.old."))
    os.replace(folder, old / "map")
    try:
        os.replace(tmp, folder)
    except BaseException:
        os.replace(old / "map", folder)
        raise
    finally:
        shutil.rmtree(old, ignore_errors=True)


def _fail(path: Path, message: str) -> MapFormatError:
    return MapFormatError(f"{path}: {message}")


def _file(folder: Path, files: dict, key: str, meta: Path) -> Path:
    name = files.get(key) if isinstance(files, dict) else None
    if not isinstance(name, str) or not name or Path(name).name != name:
        raise _fail(meta, f"'files' must name the {key} file (a plain file name), got {name!r}")
    path = folder / name
    check_input(path, "the files of magnetic field maps", MAX_FILE_BYTES, MapFormatError)
    if not path.is_file():
        raise _fail(path, f"missing {key} file of the magnetic field map")
    return path


def _read_npz(
    path: Path, shapes: dict[str, tuple], limit: float = MAGNITUDE_LIMIT
) -> dict[str, np.ndarray]:
    check_npz(path, "the files of magnetic field maps", MAX_FILE_BYTES, MapFormatError)
    try:
        with np.load(path, allow_pickle=False) as npz:
            found = {k: npz[k] for k in npz.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as err:
        raise _fail(path, f"not a readable .npz file ({err})") from None
    for key, shape in shapes.items():
        if key not in found:
            raise _fail(path, f"missing array '{key}'")
        a = found[key]
        if len(a.shape) != len(shape) or any(
            e not in (None, n) for n, e in zip(a.shape, shape, strict=False)
        ):
            raise _fail(path, f"'{key}' has shape {a.shape}, expected {shape} (see the YAML)")
        if a.dtype.kind not in "fiu" or not np.all(np.isfinite(a)):
            raise _fail(path, f"'{key}' holds NaN, infinity or non-numbers")
        if a.size and np.abs(a).max() > limit:
            raise _fail(path, f"'{key}' holds {np.abs(a).max():g}, beyond +-{limit:g}")
    return found


def _check_png_size(image: Path, shape: tuple) -> None:
    """A PNG whose header states another size than the YAML's is refused before it is decoded
    (a small PNG can state a size of gigabytes)."""
    with open(image, "rb") as f:
        head = f.read(24)
    if head.startswith(_PNG) and head[12:16] == b"IHDR":
        width, height = struct.unpack(">II", head[16:24])
        if (height, width) != tuple(shape):
            raise _fail(
                image, f"image is {(height, width)} pixels, the YAML says {shape} (rows, columns)"
            )


def _check_grid(path: Path, arrays: dict, origin: np.ndarray, resolution: float) -> None:
    if not np.array_equal(arrays["origin"], origin) or float(arrays["resolution"]) != resolution:
        raise _fail(path, "origin or resolution disagrees with the YAML")


def _check_picture_scale(meta: Path, name: str, entry: dict) -> None:
    """A layer's scale and offset say how its picture's pixels read as values (value = pixel x
    scale + offset, for other tools; kiseki reads the arrays): finite, within the arrays' bound,
    the scale >= 0, or the folder was edited by hand."""
    bound = 2 * MAGNITUDE_LIMIT
    for key, low in (("scale", 0.0), ("offset", -bound)):
        what = f"layer '{name}': {key} (value = pixel x scale + offset)"
        try:
            check_number(entry.get(key), what, low, bound)
        except ValueError as err:
            raise _fail(meta, str(err)) from None


def _read_2d(folder: Path, doc: MagneticMapDoc, meta: Path, origin, resolution, shape) -> tuple:

    files = doc.files
    layers = files.get("layers")
    if not isinstance(layers, dict):
        raise _fail(meta, "'files' must list the layer images under 'layers'")
    for name in LAYERS:
        entry = layers.get(name)
        if not isinstance(entry, dict):
            raise _fail(meta, f"layer '{name}' is not listed under files: layers")
        _check_picture_scale(meta, name, entry)
        image = _file(folder, entry, "image", meta)
        _check_png_size(image, shape)
        try:
            pixels = read_image(image)
        except RuntimeError as err:
            raise _fail(image, f"unreadable layer image ({err})") from None
        if pixels.shape != shape:
            raise _fail(
                image, f"image is {pixels.shape} pixels, the YAML says {shape} (rows, columns)"
            )
    path = _file(folder, files, "arrays", meta)
    arrays = _read_npz(path, {**dict.fromkeys(LAYERS, shape), "origin": (2,), "resolution": ()})
    _check_grid(path, arrays, origin, resolution)
    stack = {
        q: np.stack([arrays[f"{c}_{q}"] for c in COMPONENTS], axis=-1) for q in ("mean", "variance")
    }
    return stack["mean"], stack["variance"]


def _read_3d(folder: Path, doc: MagneticMapDoc, meta: Path, origin, resolution, shape) -> tuple:
    path = _file(folder, doc.files, "arrays", meta)
    full = (*shape, 3)
    arrays = _read_npz(path, {"mean": full, "variance": full, "origin": (3,), "resolution": ()})
    _check_grid(path, arrays, origin, resolution)
    return arrays["mean"], arrays["variance"]


def _read_training(
    folder: Path, doc: MagneticMapDoc, meta: Path
) -> tuple[dict | None, Path | None, Path | None]:
    """(TrainingData's arguments, training.npz, predictor.npz), each None when absent."""
    if "training" not in doc.files:
        return None, None, None
    info = doc.training
    if info is None:
        raise _fail(meta, "training: missing (files names training data it does not describe)")
    path = _file(folder, doc.files, "training", meta)
    arrays = _read_npz(path, {"X": (info.points, None), "Y": (info.points, 3)})
    names = ("inputs", "outputs", "method", "mean", "hilbert", "predictor")
    values = (arrays["X"], arrays["Y"], info.method, info.mean, info.hilbert, None)
    training = dict(zip(names, values, strict=True))
    if "predictor" in doc.files:
        if doc.kernel.model != "curl-free":
            raise _fail(meta, "files.predictor: a stored predictor is the curl-free model's")
        n = 3 * info.points  # the exact GP's factor: (3n, 3n), its lower triangle packed
        shapes = (
            {"factor_lower": (n * (n + 1) // 2,)}
            if info.method == "exact"
            else dict.fromkeys(("centre", "half_widths", "weights", "factor_lower"), (None,))
            | {"indices": (None, None)}
        )
        predictor = _file(folder, doc.files, "predictor", meta)
        # a factor or weights of a GP: any finite size (a nearly singular kernel makes them large)
        training["predictor"] = _read_npz(predictor, shapes, math.inf)
        return training, path, predictor
    return training, path, None


@dataclass(frozen=True, eq=False)
class MapFolderContents:
    """A map folder, read and checked: the keyword arguments of ``MagneticFieldMap`` but
    ``training`` (``fields``) and of ``TrainingData`` (``training``, or None), and the files a
    problem in them is reported against (``description``, the YAML; ``training_file``;
    ``predictor_file``)."""

    fields: dict
    training: dict | None
    training_file: Path | None
    predictor_file: Path | None
    description: Path


def read_map_folder(folder) -> MapFolderContents:
    """Reads a map folder written by :func:`write_map_folder` (a map is built from it by
    :func:`kiseki.magnetic.field_map.load_map_folder`). Raises FileNotFoundError when the
    folder is absent, MapFormatError naming the file for another kind of folder, a missing
    layer, shapes that disagree, NaN or a malformed description."""

    folder = Path(folder)
    if not folder.exists():
        raise FileNotFoundError(f"{folder}: no such magnetic field map folder")
    if not folder.is_dir():
        raise _fail(folder, f"not a magnetic field map (a folder holding {MAP_FILE})")
    meta = folder / MAP_FILE
    check_input(meta, error=MapFormatError)
    if not meta.is_file() and (folder / LINEAR_MAP_FILE).is_file():
        raise _fail(folder, f"a linear magnetic map ({LINEAR_MAP_FILE}), not a GP one")
    if not meta.is_file():
        raise _fail(meta, "missing: the folder is not a magnetic field map")
    try:
        raw = read_yaml_file(meta, "magnetic field map description")
        if not isinstance(raw, dict):
            raise _fail(meta, "not a magnetic field map description (not a YAML mapping)")
        doc = read_map_doc(raw, meta)  # the fields, their values and the cell counts' limits
    except ValueError as err:
        raise MapFormatError(str(err)) from None
    d, origin, resolution = doc.dimension, np.array(doc.origin), doc.resolution
    read = _read_2d if d == 2 else _read_3d
    mean, variance = read(folder, doc, meta, origin, resolution, doc.cells())
    fields = {
        "origin": origin,
        "resolution": resolution,
        "mean": mean,
        "variance": variance,
        "prior_mean": np.array(doc.prior_mean),
        "prior_variance": np.array(doc.prior_variance),
        "kernel": doc.kernel.to_kernel(),
        "units": doc.units,
        "height": doc.height if d == 2 else None,
        "provenance": doc.provenance or {},
    }
    return MapFolderContents(fields, *_read_training(folder, doc, meta), description=meta)
