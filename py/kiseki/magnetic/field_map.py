# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic field maps: the Gaussian-process mean and variance of (mx, my, mz) on a 2-D grid
or on 3-D voxels (thesis ch. 6: mean eq. 6.8, variance of the noise-free field eq. 6.9; the
pictures of Figs. 6.13 and 6.14).

In memory, ``mean`` and ``variance`` are float64 arrays shaped (ny, nx, 3) or (nz, ny, nx, 3),
index 0 at the lowest y (and z), never image-flipped; cell (j, i) of a 2-D map has its centre
at ``origin + ((i, j) + 0.5) * resolution``, and ``origin`` is the lower corner of cell 0, as
in ROS maps. Grids made by :meth:`MagneticFieldMap.from_gp` are OctoMap-aligned: the origin is
a multiple of the resolution, so every voxel is the cell of one OctoMap key at that resolution
(OctoMap: ``key = floor(c / resolution) + 32768``, centre ``(key - 32768 + 0.5) *
resolution``; voxel index i on an axis is key ``origin / resolution + 32768 + i``).

On disk a map is a folder (kind and dimension declared in ``magnetic_map.yaml``):
:func:`save_map_folder` and :func:`load_map_folder` (and the map's ``save`` and ``load``) write
and read it through :mod:`kiseki.magnetic.map_folder`, which holds the layout.

The GP behind a map (fitting, evaluating on the cells, the predictor kept for predictions) is
in :mod:`kiseki.magnetic.map_gp`; the folder's files in :mod:`kiseki.magnetic.map_folder`.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.errors import MapFormatError
from kiseki.gp import CurlFreeKernel, SquaredExponential
from kiseki.magnetic.map_cells import MAX_CELLS, cell_span
from kiseki.magnetic.map_folder import COMPONENTS, read_map_folder, write_map_folder
from kiseki.magnetic.map_gp import (
    METHODS,
    as_gp_list,
    column_kernels,
    evaluate_on_cells,
    predict_all,
    rebuild,
)

__all__ = [
    "COMPONENTS",
    "MAX_CELLS",
    "MagneticFieldMap",
    "TrainingData",
    "load_map_folder",
    "save_map_folder",
]

OCTOMAP_KEY_OFFSET = 32768  # tree_max_val of OctoMap's default 16-level tree


def _finite(name: str, value, shape: tuple | None = None) -> np.ndarray:
    array = np.array(value, dtype=np.float64)  # a copy: the map owns its arrays
    if shape is not None and array.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite (it holds NaN or infinity)")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class TrainingData:
    """The measurements a map was fitted from, kept so that predictions can re-evaluate the
    GP exactly (eqs. 6.8-6.9) at any point instead of interpolating the grid.

    inputs (n, d) metres; outputs (n, 3) field in the map's units; method "exact", "hilbert"
    (reduced rank) or "tiled" (a grid of GPs, :class:`~kiseki.gp.TiledGP`); mean "constant" or
    "zero" (the independent GPs' prior mean);
    hilbert: the reduced-rank GPs' boxes and spectral tolerances, one a GP
    (:func:`kiseki.magnetic.map_gp.hilbert_settings`; an older map's one ``"domain"`` for
    every GP and no tolerance, 1e-4), or None; predictor: the fitted GP's arrays
    (:func:`kiseki.magnetic.map_gp.predictor_state`) for predictions with no refit, or None."""

    inputs: np.ndarray
    outputs: np.ndarray
    method: str = "exact"
    mean: str = "constant"
    hilbert: Mapping | None = None  # the reduced-rank GPs' {"domains": ..., "tolerance": ...}
    predictor: Mapping[str, np.ndarray] | None = None

    def __post_init__(self) -> None:
        x = np.asarray(self.inputs)
        if x.ndim != 2 or x.shape[1] not in (2, 3) or len(x) == 0:
            raise ValueError(f"training inputs must have shape (n, 2) or (n, 3), got {x.shape}")
        object.__setattr__(self, "inputs", _finite("training inputs", x))
        object.__setattr__(self, "outputs", _finite("training outputs", self.outputs, (len(x), 3)))
        if self.method not in METHODS:
            raise ValueError(f"training method must be one of {METHODS}, got {self.method!r}")
        if self.mean not in ("constant", "zero"):
            raise ValueError(f"training mean must be constant or zero, got {self.mean!r}")
        if self.predictor is not None:
            arrays = {str(k): np.asarray(v) for k, v in dict(self.predictor).items()}
            object.__setattr__(self, "predictor", MappingProxyType(arrays))


def _check_kernel(kernel) -> SquaredExponential | tuple[SquaredExponential, ...] | CurlFreeKernel:
    if isinstance(kernel, (SquaredExponential, CurlFreeKernel)):
        return kernel
    if (
        isinstance(kernel, Sequence)
        and len(kernel) == 3
        and all(isinstance(k, SquaredExponential) for k in kernel)
    ):
        return tuple(kernel)
    raise ValueError(
        "kernel must be a SquaredExponential, three of them (one per component) or a "
        f"CurlFreeKernel, got {kernel!r}"
    )


@dataclass(frozen=True, eq=False)
class MagneticFieldMap:
    """Mean and variance of the field on a grid (2-D) or voxels (3-D); see the module text.

    kernel: the GP's hyperparameters, one SquaredExponential shared by the three components, a
    tuple of three (mx, my, mz), or the curl-free model's CurlFreeKernel. prior_mean (3,) and
    prior_variance (3,) are what the map returns outside its cells: the independent GPs' prior
    (their mean, sigma_f^2), or the curl-free GP's field far from every reading (the constant
    field's posterior, the anomaly's prior variance added: kiseki.magnetic.map_gp). height: a
    2-D map's sensor height (m) or None.
    provenance: what the map was fitted from (``data``: sources, points; ``fit``: method,
    log marginal likelihood, times), saved in the folder's YAML. training: the measurements,
    for exact predictions (:meth:`predict`), or None."""

    origin: np.ndarray
    resolution: float
    mean: np.ndarray
    variance: np.ndarray
    prior_mean: np.ndarray
    prior_variance: np.ndarray
    kernel: SquaredExponential | tuple[SquaredExponential, ...] | CurlFreeKernel
    units: str = "unknown"
    height: float | None = None
    provenance: Mapping = field(default_factory=dict)
    training: TrainingData | None = None

    def __post_init__(self) -> None:
        mean = np.asarray(self.mean)
        if mean.ndim not in (3, 4) or mean.shape[-1] != 3 or 0 in mean.shape:
            raise ValueError(
                f"mean must have shape (ny, nx, 3) or (nz, ny, nx, 3), got {mean.shape}"
            )
        d = mean.ndim - 1
        if mean.size // 3 > MAX_CELLS:
            raise ValueError(f"the map has {mean.size // 3:,} cells, more than {MAX_CELLS:,}")
        set_ = object.__setattr__
        set_(self, "mean", _finite("mean", mean))
        set_(self, "variance", _finite("variance", self.variance, mean.shape))
        if np.any(self.variance < 0):
            raise ValueError("variance must be >= 0")
        set_(self, "origin", _finite("origin", self.origin, (d,)))
        set_(
            self,
            "resolution",
            check_number(self.resolution, "resolution", 0.0, low_open=True, unit="m"),
        )
        set_(self, "prior_mean", _finite("prior_mean", self.prior_mean, (3,)))
        set_(self, "prior_variance", _finite("prior_variance", self.prior_variance, (3,)))
        if np.any(self.prior_variance <= 0):
            raise ValueError("prior_variance must be > 0")
        set_(self, "kernel", _check_kernel(self.kernel))
        if not isinstance(self.units, str) or not self.units:
            raise ValueError(f"units must be a non-empty string, got {self.units!r}")
        if self.height is not None:
            if d == 3:
                raise ValueError("height is for 2-D maps: a 3-D map has z in its voxels")
            set_(self, "height", check_number(self.height, "height", unit="m"))
        set_(self, "provenance", MappingProxyType(dict(self.provenance)))
        if self.training is not None:
            if not isinstance(self.training, TrainingData):
                raise ValueError(f"training must be TrainingData, got {type(self.training)}")
            need = (d,) if self.height is None else (d, d + 1)
            if self.training.inputs.shape[1] not in need:
                raise ValueError(
                    f"training inputs have {self.training.inputs.shape[1]} coordinates; a "
                    f"{d}-D map needs {' or '.join(map(str, need))}"
                )
        set_(self, "_regressors", None)

    @property
    def dimension(self) -> int:
        """2 (a grid over x, y) or 3 (voxels over x, y, z)."""
        return self.mean.ndim - 1

    @property
    def cells(self) -> tuple[int, ...]:
        """Number of cells along x, y[, z] (the arrays' shape reversed)."""
        return tuple(self.mean.shape[:-1][::-1])

    @property
    def lower(self) -> np.ndarray:
        """World coordinates of the map's lower corner (= origin)."""
        return self.origin.copy()

    @property
    def upper(self) -> np.ndarray:
        """World coordinates of the map's upper corner."""
        return self.origin + np.array(self.cells) * self.resolution

    def cell_centres(self) -> np.ndarray:
        """(N, d) centres in x, y[, z] order, in the arrays' C order (x fastest)."""
        return _centres(self.origin, self.resolution, self.mean.shape[:-1], 0, self.mean.size // 3)

    def octomap_key_origin(self) -> np.ndarray:
        """The OctoMap key (16-level tree) of cell 0: cell (i, j[, k]) has key origin + (i, j[,
        k]). Raises ValueError when the origin is not a multiple of the resolution."""
        steps = self.origin / self.resolution
        if not np.allclose(steps, np.round(steps), rtol=0, atol=1e-6):
            raise ValueError(f"origin {self.origin} is not a multiple of {self.resolution} m")
        return np.round(steps).astype(np.int64) + OCTOMAP_KEY_OFFSET

    def value_at(self, points) -> tuple[np.ndarray, np.ndarray]:
        """(mean (m, 3), variance (m, 3)) at world points (m, d): (bi/tri)linear interpolation
        between cell centres (constant within the outer half cell), the GP prior (prior_mean,
        prior_variance) outside the map."""
        p = _points(points, self.dimension)
        n = np.array(self.cells)
        u = (p - self.origin) / self.resolution  # 0 .. n across the map
        inside = np.all((u >= 0) & (u <= n), axis=1)
        c = np.clip(u[inside] - 0.5, 0, n - 1)  # coordinates of the cell centres' lattice
        i0 = np.minimum(np.floor(c).astype(np.int64), np.maximum(n - 2, 0))
        t = c - i0
        mean = np.tile(self.prior_mean, (len(p), 1))
        var = np.tile(self.prior_variance, (len(p), 1))
        m_in = np.zeros((len(c), 3))
        v_in = np.zeros((len(c), 3))
        for corner in itertools.product((0, 1), repeat=self.dimension):
            index = np.minimum(i0 + corner, n - 1)
            w = np.prod(np.where(np.array(corner, dtype=bool), t, 1.0 - t), axis=1)[:, None]
            cell = tuple(index[:, k] for k in reversed(range(self.dimension)))
            m_in += w * self.mean[cell]
            v_in += w * self.variance[cell]
        mean[inside], var[inside] = m_in, v_in
        return mean, var

    def predict(self, points, *, release: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """(mean (m, 3), variance (m, 3)) of the GP itself at world points (m, d) (eqs. 6.8,
        6.9): a curl-free map's GP comes from its stored factor (no refit); the independent
        GPs are rebuilt once from the stored training data with the stored hyperparameters
        (no optimisation). A 2-D map made from a 3-D GP predicts at its height. release: a
        tiled map frees each tile's factor once its points are done (points asked once: one
        tile in memory; later calls factorise the tiles again). Raises ValueError when the
        map keeps no training data."""
        p = _points(points, self.dimension)
        if self.training is None:
            raise ValueError("the map keeps no training data: use value_at (interpolation)")
        if self.training.inputs.shape[1] == self.dimension + 1:
            p = np.column_stack([p, np.full(len(p), self.height)])
        if self._regressors is None:
            object.__setattr__(self, "_regressors", rebuild(self.training, self.kernel))
        return predict_all(self._regressors, p, release=release)

    @classmethod
    def from_gp(
        cls,
        gp,
        lower,
        upper,
        resolution: float,
        height: float | None = None,
        *,
        units: str = "unknown",
        provenance: Mapping | None = None,
        training: TrainingData | None = None,
        progress: bool = False,
    ) -> MagneticFieldMap:
        """The map of a fitted GP (``ExactGP``/``HilbertGP``, three one-output GPs for
        mx, my, mz, or a curl-free GP) over the box lower..upper (d,) at `resolution`: the
        grid is OctoMap-aligned (origin floor(lower / resolution) * resolution, upper corner
        rounded up), and gp.predict
        is evaluated on the cell centres in chunks (a tqdm bar when `progress`). A 2-D box with
        a 3-D GP gives the horizontal slice at `height`."""
        gps = as_gp_list(gp)
        lo = _finite("lower", lower)
        hi = _finite("upper", upper)
        if lo.ndim != 1 or lo.shape not in ((2,), (3,)) or hi.shape != lo.shape:
            raise ValueError(f"lower and upper must be (2,) or (3,), got {lo.shape}, {hi.shape}")
        if np.any(hi < lo):
            raise ValueError(f"upper {hi} must not be below lower {lo} on any axis")
        d, gd = len(lo), gps[0].dimension
        if gd != d and not (d == 2 and gd == 3 and height is not None):
            hint = " (give height for a 2-D slice of a 3-D GP)" if (d, gd) == (2, 3) else ""
            raise ValueError(f"the GP is {gd}-D but the box is {d}-D{hint}")
        check_number(resolution, "resolution", 0.0, low_open=True, unit="m")
        first, last, counts = cell_span(lo, hi, resolution)
        if d == 3 and np.any(np.abs(np.concatenate([first, last])) > OCTOMAP_KEY_OFFSET):
            raise ValueError(f"the box {lo}..{hi} lies beyond OctoMap's keys at {resolution} m")
        cells = float(np.prod(counts.astype(float)))  # in int64, 2**32 x 2**32 cells made 0
        if cells > MAX_CELLS:
            raise ValueError(
                f"{' x '.join(map(str, counts))} cells at {resolution} m is {cells:,.0f} cells, "
                f"more than {MAX_CELLS:,}: choose a coarser resolution or a smaller box"
            )
        total = int(cells)
        origin = first * float(resolution)
        shape = tuple(int(k) for k in counts[::-1])
        at = height if gd > d else None

        def centres(start: int, stop: int) -> np.ndarray:
            p = _centres(origin, resolution, shape, start, stop)
            return p if at is None else np.column_stack([p, np.full(len(p), at)])

        mean, var = evaluate_on_cells(gps, centres, total, progress)
        mean, var = mean.reshape(*shape, 3), var.reshape(*shape, 3)
        kernels = column_kernels(gps)
        kernel = kernels[0] if len(set(kernels)) == 1 else kernels
        return cls(
            origin=origin,
            resolution=float(resolution),
            mean=mean,
            variance=var,
            prior_mean=np.concatenate([np.atleast_1d(g.prior_mean) for g in gps]),
            prior_variance=np.concatenate([np.atleast_1d(g.prior_variance) for g in gps]),
            kernel=kernel,
            units=units,
            height=height if d == 2 else None,
            provenance=provenance or {},
            training=training,
        )

    def save(self, folder) -> None:
        """Writes the map folder (write-then-rename of the whole folder): save_map_folder."""
        save_map_folder(self, folder)

    @classmethod
    def load(cls, folder) -> MagneticFieldMap:
        """Reads a map folder (MapFormatError naming the file): load_map_folder."""
        return load_map_folder(folder)


def save_map_folder(fmap: MagneticFieldMap, folder) -> Path:
    """Writes `fmap` to `folder` (the layout: :mod:`kiseki.magnetic.map_folder`): a temporary
    folder beside it, renamed into place; an existing map folder (or an empty folder) is
    replaced, anything else refused. Returns the folder as a Path."""
    if not isinstance(fmap, MagneticFieldMap):
        raise ValueError(f"expected a MagneticFieldMap, got {type(fmap).__name__}")
    return write_map_folder(fmap, folder)


def load_map_folder(folder) -> MagneticFieldMap:
    """The map in a folder written by :func:`save_map_folder`. Raises FileNotFoundError when the
    folder is absent, MapFormatError naming the file for another kind of folder, a missing
    layer, shapes that disagree, NaN or a malformed description."""
    contents = read_map_folder(folder)
    training = None
    if contents.training is not None:
        try:
            training = TrainingData(**contents.training)
        except ValueError as err:
            raise MapFormatError(f"{contents.training_file}: {err}") from None
    try:
        fmap = MagneticFieldMap(**contents.fields, training=training)
    except ValueError as err:
        raise MapFormatError(f"{contents.description}: {err}") from None
    if training is not None and training.predictor is not None:
        try:  # the stored GP, checked against the readings and the kernel now
            object.__setattr__(fmap, "_regressors", rebuild(training, fmap.kernel))
        except (ValueError, KeyError, TypeError) as err:
            raise MapFormatError(f"{contents.predictor_file}: {err}") from None
    return fmap


def _points(points, d: int) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 1 and p.shape == (d,):
        p = p[None]
    if p.ndim != 2 or p.shape[1] != d:
        raise ValueError(f"points must have shape (m, {d}) for a {d}-D map, got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise ValueError("points must be finite (they hold NaN or infinity)")
    return p


def _centres(origin, resolution, shape, start: int, stop: int) -> np.ndarray:
    """Centres of the cells with flat C-order indices start..stop of an array shaped `shape`
    ((ny, nx) or (nz, ny, nx)), in x, y[, z] order."""
    index = np.unravel_index(np.arange(start, stop), shape)
    return origin + (np.column_stack(index[::-1]) + 0.5) * resolution
