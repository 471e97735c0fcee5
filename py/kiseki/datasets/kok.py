# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Hand-held magnetometer walks in the MATLAB v5 layout of Kok and Solin, "Online
One-Dimensional Magnetic Field SLAM with Loop-Closure Detection" (MFI 2024): an iPad's
magnetometer with ARKit visual-inertial odometry at 10 Hz.

Variables used: ``t`` (N x 1, s), ``dPos`` (N-1 x 3 position increments, m, world frame with z
up), ``quat`` (N x 4 orientation), ``m`` (N x 3 magnetometer, uT, sensor frame). Positions are
``[0; cumsum(dPos)]`` (N rows, starting at the origin, as in the authors' ``prepareData.m``).

The orientation convention, found from the data. The Earth field is constant in the world frame,
so the right convention turns the readings into vectors that keep nearly one direction while the
iPad turns (indoor anomalies add a spatial part that no convention removes). Sixteen candidates
were compared on both walks: quaternion order (w, x, y, z) or (x, y, z, w), the matrix R(q) taken
as body-to-world (world = R m) or world-to-body (world = R^T m), and the magnetometer's axes
turned by 0, 90, 180 or 270 degrees about z in the ARKit body frame. The spread of the world field
(norm of its per-component SD over the walk, uT):

* ``eight.mat`` (466 samples): 13.0 for (w, x, y, z), body-to-world, mount Rz(+90 deg); the next
  best 18.4 (x, y, z, w; R; 180 deg), the others 22-45; the raw sensor-frame readings 15.0;
* ``square.mat`` (747 samples): 14.4 for the same convention; the next 16.5 and 16.6, the others
  20-54; the raw readings 18.7.

The winner is also the only low-spread candidate that is physically right: its mean field is
(2.4, -14.2, -41.7) uT on ``eight`` and (-5.0, -12.5, -51.3) uT on ``square``, i.e. pointing
down along the axis in which the positions hardly change (z spans 0.3 m, x and y 2-7 m), with an
inclination of 71-75 deg, as at northern European latitudes; the next candidates put the large
component on a horizontal axis. Over all 24 axis-aligned mounts the same rotation wins (tied only
with its algebraic twin (x, y, z, w) with R^T, which also puts the vertical field on x). The
convention agrees with the authors' code, which turns the magnetometer frame to ARKit's by
``rotz(-pi/2)`` of their transposed ``rotz``, i.e. Rz(+90 deg).

Hence: ``field_world = R(q) @ Rz(+90 deg) @ m`` with q = (w, x, y, z) and R(q) the usual
body-to-world rotation matrix of a unit quaternion.

The readings are as recorded, not recalibrated. ``eight.mat`` carries an uncompensated offset:
subtracting a constant sensor-frame vector of about (12.1, -12.6, 2.5) uT (least squares, with
the convention above) shrinks the world field's SD from (8.5, 9.7, 1.7) to (2.1, 1.1, 0.9) uT and
the SD of |m| from 3.7 to 0.9 uT (:mod:`kiseki.magnetic.calibration` fits such offsets).
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from kiseki._support.inputs import MIB, check_input, decompressed_size, describe_bytes
from kiseki.datasets.magnetic_samples import MagneticSamples
from kiseki.errors import LogFormatError

__all__ = ["MAX_MAT_BYTES", "SENSOR_TO_BODY", "quaternion_to_matrix", "read_kok_walk"]

MAX_MAT_BYTES = 256 * MIB
"""A walk's ``.mat`` file, and what its compressed variables inflate to, hold at most this
(``square.mat``: 80 KB; an hour at 10 Hz of its four variables is 1.6 MB)."""
_MI_COMPRESSED = 15  # MATLAB v5 data element type of a zlib-compressed variable
_MAT_HEADER = 128

# The magnetometer's axes in the ARKit body frame: a rotation of +90 deg about z.
SENSOR_TO_BODY = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
SENSOR_TO_BODY.setflags(write=False)

_UNIT_TOLERANCE = 1e-3


def quaternion_to_matrix(quat: np.ndarray) -> np.ndarray:
    """(n, 3, 3) body-to-world rotation matrices of unit quaternions (n, 4) ordered w, x, y, z
    (Hamilton product, active rotation: world = R @ body)."""
    q = np.asarray(quat, dtype=np.float64)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"quaternions must be (n, 4) ordered w, x, y, z, got {q.shape}")
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


POSITION_LIMIT = 1e6  # m: a hand-held walk stays within a building, not 1,000 km
TIME_LIMIT = 1e10  # s: clock times of this century (Unix time is about 1.8e9 s)


def read_kok_walk(path: str | os.PathLike) -> MagneticSamples:
    """A walk from a MATLAB v5 ``.mat`` file: 3-D positions ``[0; cumsum(dPos)]``, the field
    turned to the world frame (see the module docstring for the convention), uT, times ``t``."""
    path = Path(path)
    data = _load_mat(path)
    t, dpos, quat, m = (data[name] for name in ("t", "dPos", "quat", "m"))
    n = len(m)
    if m.ndim != 2 or m.shape[1] != 3 or n < 2:
        raise LogFormatError(f"{path}: m must be N x 3 with N >= 2, got {m.shape}")
    if quat.shape != (n, 4):
        raise LogFormatError(f"{path}: quat must be {n} x 4 like m ({n} x 3), got {quat.shape}")
    if dpos.shape != (n - 1, 3):
        raise LogFormatError(
            f"{path}: dPos must be {n - 1} x 3 (one increment between consecutive samples of m, "
            f"{n} x 3), got {dpos.shape}"
        )
    if t.size != n:
        raise LogFormatError(f"{path}: t must hold {n} times like m, got shape {t.shape}")
    times = t.reshape(-1).astype(np.float64)
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(times) <= TIME_LIMIT)  # NaN too
        bad[1:] |= ~(times[1:] > times[:-1])
    if bad.any():
        row = int(np.argmax(bad))
        after = f" after {float(times[row - 1])!r}" if row else ""
        raise LogFormatError(
            f"{path}: t must increase from sample to sample, finite within +-{TIME_LIMIT:g} s; "
            f"sample {row + 1} is {float(times[row])!r}{after}"
        )
    norms = np.linalg.norm(quat, axis=1)
    bad = ~(np.abs(norms - 1.0) <= _UNIT_TOLERANCE)
    if bad.any():
        row = int(np.argmax(bad))
        raise LogFormatError(
            f"{path}: quat row {row + 1} is not a unit quaternion (norm {norms[row]:.6g})"
        )
    with np.errstate(over="ignore", invalid="ignore"):  # a huge increment is refused below
        positions = np.vstack([np.zeros(3), np.cumsum(dpos, axis=0)])
    far = ~(np.abs(positions) <= POSITION_LIMIT).all(axis=1)
    if far.any():
        row = int(np.argmax(far))
        raise LogFormatError(
            f"{path}: dPos takes the walk to {positions[row].tolist()} m at sample {row + 1}: "
            f"not finite within +-{POSITION_LIMIT:g} m"
        )
    rotation = quaternion_to_matrix(quat / norms[:, None]) @ SENSOR_TO_BODY
    field = np.einsum("nij,nj->ni", rotation, m)
    return MagneticSamples(positions, field, "uT", str(path), t.reshape(-1))


def _load_mat(path: Path) -> dict[str, np.ndarray]:
    import scipy.io  # here, so that importing kiseki.datasets does not load scipy

    check_input(path, "MATLAB .mat walks", MAX_MAT_BYTES, LogFormatError)
    if path.is_dir():
        raise LogFormatError(f"{path}: a directory, not a .mat file")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: file not found")
    _check_inflated_size(path)
    try:
        contents = scipy.io.loadmat(path)
    except NotImplementedError as exc:  # MATLAB v7.3 files are HDF5
        raise LogFormatError(f"{path}: MATLAB v7.3 (HDF5) files are not read: {exc}") from exc
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError... on bad bytes
        raise LogFormatError(f"{path}: not a MATLAB v5 .mat file ({exc})") from exc
    missing = [name for name in ("t", "dPos", "quat", "m") if name not in contents]
    if missing:
        found = ", ".join(k for k in contents if not k.startswith("__")) or "none"
        raise LogFormatError(
            f"{path}: not a Kok-Solin walk: lacks {', '.join(missing)} (variables found: {found})"
        )
    arrays = {}
    for name in ("t", "dPos", "quat", "m"):
        # a complex array lost its imaginary part with a numpy warning
        if np.asarray(contents[name]).dtype.kind in "cb":
            raise LogFormatError(
                f"{path}: {name} is a {np.asarray(contents[name]).dtype} array, not real numbers"
            )
        try:
            arrays[name] = np.asarray(contents[name], dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise LogFormatError(f"{path}: {name} is not a numeric array ({exc})") from exc
    return arrays


def _check_inflated_size(path: Path) -> None:
    """Refuses a MATLAB v5 file whose compressed variables inflate to more than MAX_MAT_BYTES
    (scipy inflates each whole, sized by the header inside it), counted by inflating them in
    pieces. Anything that is not a v5 file's element list is left to scipy to report."""
    data = path.read_bytes()  # within MAX_MAT_BYTES: checked by the caller
    if len(data) < _MAT_HEADER or data[126:128] not in (b"IM", b"MI"):
        return
    order = "<" if data[126:128] == b"IM" else ">"
    total, at = 0, _MAT_HEADER
    while at + 8 <= len(data):
        kind, count = struct.unpack_from(f"{order}II", data, at)
        if kind >> 16:  # a small element: its data sits in the tag's 8 bytes
            at += 8
            continue
        body = data[at + 8 : at + 8 + count]
        if kind == _MI_COMPRESSED:
            left = MAX_MAT_BYTES - total
            try:
                inflated = decompressed_size(body, "zlib", left)
            except Exception:  # noqa: BLE001 (a corrupt stream: scipy reports it)
                return
            total += inflated
            if inflated > left:
                raise LogFormatError(
                    f"{path}: its variables decompress to more than "
                    f"{describe_bytes(MAX_MAT_BYTES)} (kiseki's limit for MATLAB .mat walks)"
                )
        at += 8 + count
