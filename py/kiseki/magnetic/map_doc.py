# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a magnetic field map folder's description, ``magnetic_map.yaml`` (written by
:func:`kiseki.magnetic.field_map.save_map_folder`; it may have been edited by hand)::

    kind: magnetic_field_map
    format_version: 1
    dimension: 2                    # 2 or 3
    origin: [-1.0, -2.0]            # one number per dimension (m)
    resolution: 0.25                # m
    shape: {x: 40, y: 30}           # cells (voxels) along x, y[, z]
    units: uT
    prior_mean: [0.0, 0.0, 0.0]
    prior_variance: [1.0, 1.0, 1.0]
    kernel: {sigma_f: 3, length_scale: 1, sigma_n: 0.1}   # or one per mx, my, mz, or
    # {model: curl-free, sigma_f: 3, length_scale: 1, sigma_lin: 40, sigma_n: 0.1}
    training: {points: 400, method: exact, mean: constant}   # when training.npz is kept
    files: {...}                    # the layers, arrays, training data and predictor

A problem is one line naming the file, the field and the value
(``magnetic_map.yaml: shape.x: must be less than or equal to 10000000, got 99999999``): the
cell counts are limited (:data:`MAX_MAP_CELLS`) so that a hand-edited file cannot ask for any
memory. :func:`describe_map` writes the description of a map."""

from __future__ import annotations

import math
import os
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from kiseki import __version__
from kiseki._support.schema import FileModel, FiniteFloat, PositiveFloat, parse
from kiseki.gp import CurlFreeKernel, SquaredExponential

__all__ = [
    "COMPONENTS",
    "KIND",
    "MAX_MAP_CELLS",
    "MAX_TRAINING_POINTS",
    "MagneticMapDoc",
    "describe_map",
    "read_map_doc",
]

COMPONENTS = ("mx", "my", "mz")
"""The field's components, in the order of the maps' last axis and of the layers' names."""
KIND = "magnetic_field_map"
FORMAT_VERSION = 1

MAX_MAP_CELLS = 10_000_000
"""Cells (2-D) or voxels (3-D) of a map, along one axis and in all: a cell's mean and variance
(3 components, float64) take 48 bytes, so 480 MB for the limit, read from the .npz and again
into the map."""
MAX_TRAINING_POINTS = 10_000_000
"""Stored measurements (training.npz): 48 bytes each (a 3-D position and a 3-D field)."""

CellCount = Annotated[int, Field(strict=True, gt=0, le=MAX_MAP_CELLS)]
Text = Annotated[str, Field(strict=True, max_length=4096)]
Triple = tuple[FiniteFloat, FiniteFloat, FiniteFloat]


class Kernel(FileModel):
    """A squared-exponential kernel: sigma_f, length_scale (m), sigma_n."""

    sigma_f: PositiveFloat
    length_scale: PositiveFloat
    sigma_n: PositiveFloat


class KernelDoc(FileModel):
    """The map's kernel: one for the three components (sigma_f, length_scale, sigma_n), one
    per component (mx, my, mz), or the curl-free model's (model: curl-free, sigma_f,
    length_scale, sigma_lin, sigma_n)."""

    model: Literal["independent", "curl-free"] = "independent"
    sigma_f: PositiveFloat | None = None
    length_scale: PositiveFloat | None = None
    sigma_lin: PositiveFloat | None = None
    sigma_n: PositiveFloat | None = None
    mx: Kernel | None = None
    my: Kernel | None = None
    mz: Kernel | None = None

    @model_validator(mode="after")
    def _one_form(self) -> KernelDoc:
        one = (self.sigma_f, self.length_scale, self.sigma_n)
        each = (self.mx, self.my, self.mz)
        if self.model == "curl-free":
            if None in one or self.sigma_lin is None or each != (None,) * 3:
                raise ValueError(
                    "model curl-free must hold sigma_f, length_scale, sigma_lin and sigma_n"
                )
            return self
        if self.sigma_lin is not None:
            raise ValueError("sigma_lin is the curl-free model's (model: curl-free)")
        if not (None not in one and each == (None,) * 3 or None not in each and one == (None,) * 3):
            raise ValueError(
                "must hold sigma_f, length_scale, sigma_n or one such entry per mx, my, mz"
            )
        return self

    def to_kernel(self) -> SquaredExponential | tuple[SquaredExponential, ...] | CurlFreeKernel:
        """The kernel object a map holds."""
        if self.model == "curl-free":
            return CurlFreeKernel(self.sigma_f, self.length_scale, self.sigma_lin, self.sigma_n)
        if self.mx is not None:
            return tuple(
                SquaredExponential(k.sigma_f, k.length_scale, k.sigma_n)
                for k in (self.mx, self.my, self.mz)  # type: ignore[union-attr]
            )
        return SquaredExponential(self.sigma_f, self.length_scale, self.sigma_n)


class Shape(FileModel):
    """Cells along x, y (and z for a 3-D map)."""

    x: CellCount
    y: CellCount
    z: CellCount | None = None


class TrainingInfo(FileModel):
    """The stored measurements (training.npz): how many, and the GP they were fitted with."""

    points: Annotated[int, Field(strict=True, gt=0, le=MAX_TRAINING_POINTS)]
    method: Text | None = None  # checked by kiseki.magnetic.field_map.TrainingData
    mean: Text | None = None
    hilbert: dict[str, Any] | None = None


class MagneticMapDoc(FileModel):
    """A whole ``magnetic_map.yaml`` (see the module docstring)."""

    kind: Literal["magnetic_field_map"]
    format_version: Literal[1]
    dimension: Literal[2, 3]
    origin: list[FiniteFloat]
    resolution: PositiveFloat
    shape: Shape
    units: Text
    variance_units: Text | None = None
    frame: Literal["world"] = "world"
    prior_mean: Triple
    prior_variance: Triple
    kernel: KernelDoc
    height: FiniteFloat | None = None
    image_rows: Text | None = None
    layout: Text | None = None
    octomap_key_origin: list[Annotated[int, Field(strict=True)]] | None = None
    training: TrainingInfo | None = None
    provenance: dict[str, Any] | None = None
    kiseki_version: Text | None = None
    files: dict[str, Any]

    @field_validator("origin")
    @classmethod
    def _one_per_axis(cls, origin: list[float], info: ValidationInfo) -> list[float]:
        d = info.data.get("dimension")
        if d is not None and len(origin) != d:
            raise ValueError(f"must be a list of {d} numbers (the map is {d}-D)")
        return origin

    @field_validator("shape")
    @classmethod
    def _cells(cls, shape: Shape, info: ValidationInfo) -> Shape:
        d = info.data.get("dimension")
        if d is not None and (shape.z is None) != (d == 2):
            raise ValueError(f"must give the cell counts of {', '.join('xyz'[:d])}")
        cells = math.prod(c for c in (shape.x, shape.y, shape.z) if c is not None)
        if cells > MAX_MAP_CELLS:
            raise ValueError(f"at most {MAX_MAP_CELLS:,} cells in all (here {cells:,})")
        return shape

    def cells(self) -> tuple[int, ...]:
        """The map's array shape: (ny, nx) or (nz, ny, nx)."""
        axes = (self.shape.x, self.shape.y, self.shape.z)[: self.dimension]
        return tuple(reversed(axes))


def read_map_doc(doc: Any, path: str | os.PathLike) -> MagneticMapDoc:
    """`doc` (the parsed ``magnetic_map.yaml`` at `path`) checked against
    :class:`MagneticMapDoc`: a :class:`~kiseki._support.schema.SchemaError` naming the file, the
    field and the value."""
    return parse(MagneticMapDoc, doc, path)


def _plain(value):
    if isinstance(value, dict | type(None)) or hasattr(value, "items"):
        return None if value is None else {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def _kernel_doc(kernel) -> dict:
    def one(k: SquaredExponential) -> dict:
        return {
            "sigma_f": float(k.sigma_f),
            "length_scale": float(k.length_scale),
            "sigma_n": float(k.sigma_n),
        }

    if isinstance(kernel, CurlFreeKernel):
        return {"model": "curl-free", **{k: float(v) for k, v in kernel.to_dict().items()}}
    if isinstance(kernel, SquaredExponential):
        return one(kernel)
    return {c: one(k) for c, k in zip(COMPONENTS, kernel, strict=True)}


def describe_map(fmap, files: dict) -> dict:
    """The ``magnetic_map.yaml`` of a map (a MagneticFieldMap) whose files are `files`."""
    d = fmap.dimension
    doc = {
        "kind": KIND,
        "format_version": FORMAT_VERSION,
        "dimension": d,
        "origin": [float(v) for v in fmap.origin],
        "resolution": fmap.resolution,
        "shape": dict(zip("xyz", fmap.cells, strict=False)),
        "units": fmap.units,
        "variance_units": f"({fmap.units})^2",
        "frame": "world",
        "prior_mean": [float(v) for v in fmap.prior_mean],
        "prior_variance": [float(v) for v in fmap.prior_variance],
        "kernel": _kernel_doc(fmap.kernel),
    }
    if d == 2:
        doc["height"] = fmap.height
        doc["image_rows"] = "row 0 is the top of the map (highest y), as ROS map images"
    else:
        doc["layout"] = "octomap: voxel centre = origin + (index + 0.5) * resolution"
        try:
            doc["octomap_key_origin"] = [int(k) for k in fmap.octomap_key_origin()]
        except ValueError:
            doc["layout"] = "voxel centre = origin + (index + 0.5) * resolution"
    if fmap.training is not None:
        t = fmap.training
        doc["training"] = {"points": len(t.inputs), "method": t.method, "mean": t.mean}
        if t.hilbert is not None:
            doc["training"]["hilbert"] = _plain(dict(t.hilbert))
    doc["provenance"] = _plain(dict(fmap.provenance))
    doc["kiseki_version"] = __version__
    doc["files"] = files
    return doc
