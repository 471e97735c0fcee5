# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic-field samples as kiseki's own type: :class:`MagneticSamples` (positions, the field
vector there, its units, the times) and :func:`concatenate_samples`.

Every reader of recorded magnetic data returns this type (:mod:`kiseki.datasets.magnetic` for
CSV files and Aalto runs, :mod:`kiseki.datasets.kok` for Kok-Solin walks); the readers import it
from here, not from one another.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kiseki._support.schema import MAGNITUDE_LIMIT

__all__ = ["UNITS", "MagneticSamples", "concatenate_samples"]

UNITS = ("uT", "G", "unknown")


@dataclass(frozen=True, eq=False)
class MagneticSamples:
    """Magnetic-field vectors measured at known positions, in one world frame.

    ``positions`` (n, 2) or (n, 3) in metres; ``field`` (n, 3), the field's components along the
    x, y, z axes of the positions' frame; ``units`` one of ``"uT"``, ``"G"`` or ``"unknown"`` (a
    sensor whose units are not stated); ``source`` the file or prefix the samples came from;
    ``times`` (n,) in seconds or None. The arrays are stored as read-only float64 copies.
    """

    positions: np.ndarray
    field: np.ndarray
    units: str
    source: str
    times: np.ndarray | None = None

    def __post_init__(self) -> None:
        source = str(self.source)
        object.__setattr__(self, "source", source)
        if self.units not in UNITS:
            raise ValueError(f"{source}: units {self.units!r} not one of {', '.join(UNITS)}")
        positions = _frozen_array(self.positions, source, "positions")
        field = _frozen_array(self.field, source, "field")
        if positions.ndim != 2 or positions.shape[1] not in (2, 3):
            raise ValueError(f"{source}: positions must be (n, 2) or (n, 3), got {positions.shape}")
        if field.ndim != 2 or field.shape[1] != 3:
            raise ValueError(f"{source}: field must be (n, 3), got {field.shape}")
        if len(positions) != len(field):
            raise ValueError(
                f"{source}: {len(positions)} positions but {len(field)} field readings"
            )
        if len(positions) == 0:
            raise ValueError(f"{source}: no samples")
        _check_finite(positions, source, "position", MAGNITUDE_LIMIT)
        _check_finite(field, source, "field reading", MAGNITUDE_LIMIT)
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "field", field)
        if self.times is not None:
            times = _frozen_array(self.times, source, "times")
            if times.shape != (len(positions),):
                raise ValueError(
                    f"{source}: times must be ({len(positions)},) like the positions, "
                    f"got {times.shape}"
                )
            _check_finite(times[:, None], source, "time")
            object.__setattr__(self, "times", times)

    def __len__(self) -> int:
        return len(self.positions)

    @property
    def dimension(self) -> int:
        """2 or 3: the number of position coordinates."""
        return self.positions.shape[1]

    @property
    def magnitude(self) -> np.ndarray:
        """(n,) field strength |m| in the samples' units."""
        return np.linalg.norm(self.field, axis=1)

    def take(self, index: np.ndarray | slice | Sequence[int]) -> MagneticSamples:
        """The samples selected by an index array, a boolean mask or a slice."""
        times = None if self.times is None else self.times[index]
        return MagneticSamples(
            self.positions[index], self.field[index], self.units, self.source, times
        )


def concatenate_samples(
    samples: Sequence[MagneticSamples], source: str | None = None
) -> MagneticSamples:
    """The samples of several runs in one set (same units and dimension required). Times are
    kept only when every run has them; ``source`` defaults to the sources joined by '+'."""
    if len(samples) == 0:
        raise ValueError("no samples to concatenate")
    units = {s.units for s in samples}
    if len(units) > 1:
        names = ", ".join(f"{s.source} ({s.units})" for s in samples)
        raise ValueError(f"cannot combine samples in different units: {names}")
    dimensions = {s.dimension for s in samples}
    if len(dimensions) > 1:
        names = ", ".join(f"{s.source} ({s.dimension}-D)" for s in samples)
        raise ValueError(f"cannot combine 2-D and 3-D positions: {names}")
    with_times = all(s.times is not None for s in samples)
    return MagneticSamples(
        np.concatenate([s.positions for s in samples]),
        np.concatenate([s.field for s in samples]),
        samples[0].units,
        source if source is not None else "+".join(s.source for s in samples),
        np.concatenate([s.times for s in samples]) if with_times else None,
    )


def _frozen_array(values: object, source: str, name: str) -> np.ndarray:
    try:
        array = np.array(values, dtype=np.float64, copy=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{source}: {name} are not numbers ({exc})") from exc
    array.setflags(write=False)
    return array


def _check_finite(array: np.ndarray, source: str, what: str, limit: float = np.inf) -> None:
    """Every row finite and, with a limit, within +-limit (a position of 1e300 m once overflowed
    the fit's squared distances)."""
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(array) & (np.abs(array) <= limit)).all(axis=1)
    if bad.any():
        row, count = int(np.argmax(bad)), int(bad.sum())
        rows = "1 row" if count == 1 else f"{count} rows"
        kind = "NaN or infinite" if np.isinf(limit) else f"NaN, infinite or beyond +-{limit:g}"
        raise ValueError(
            f"{source}: {rows} with a {kind} {what}, the first in data row {row + 1} "
            f"(counting from 1): {array[row].tolist()}"
        )
