# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Ray casters for many rays per map: the ranges of a beam model's expected readings z*.

Both casters return cast_ray's ranges to rounding, with nav2's stopping rule (an occupied cell,
an unknown one when ``unknown_stops``, the edge of the map):

* ``distance-field`` (``RangeCaster``): the Amanatides and Woo cell walk, skipping free space by
  a Euclidean distance field (4 bytes per cell).
* ``swept-sector`` (``SectorCaster``): the cell walk jumping over lines of cells that no ray of
  its heading sector can stop in, from a table of one byte per cell and sector (8 x
  ``sectors_per_octant`` sectors, 64 by default) built once per map; a scan's rays walk in
  turns to hide the table's cache misses. Several times faster per ray
  (``benchmarks/bench_ray_casting.py`` prints the figures).

``RAY_CASTERS`` names them for configs (:func:`ray_caster` checks a name); ``DEFAULT_RAY_CASTER``
is the beam model's default, read from the C++ ``BeamModelParams`` that holds it.
"""

from __future__ import annotations

from kiseki import _core
from kiseki._core import RangeCaster, SectorCaster

__all__ = ["DEFAULT_RAY_CASTER", "RAY_CASTERS", "RangeCaster", "SectorCaster", "ray_caster"]

RAY_CASTERS = {
    "swept-sector": _core.RayCaster.swept_sector,
    "distance-field": _core.RayCaster.distance_field,
}
DEFAULT_RAY_CASTER = next(k for k, v in RAY_CASTERS.items() if v == _core.BEAM_MODEL_CASTER)


def ray_caster(name: str) -> _core.RayCaster:
    """The C++ caster a config names; ValueError naming the choices for any other name."""
    if name not in RAY_CASTERS:
        raise ValueError(f"caster must be one of {', '.join(RAY_CASTERS)}, got {name!r}")
    return RAY_CASTERS[name]
