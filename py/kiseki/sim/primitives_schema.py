# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The models of a scene file's ``objects:`` entries (one per primitive type: wall, partition,
box, workbench, shelf, slope, rubble, beam, pillar), checked by :mod:`kiseki._support.schema`.

Lengths in metres, angles in degrees. Every entry has a ``type``, may carry an ``id`` (a label)
and ``only_in: teach | playback``. :attr:`box_count` says how many boxes an entry expands to
before anything is built, so that a scene can refuse a world too large to ray cast.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, PlainValidator, RootModel, model_validator

from kiseki._support.schema import FileModel, FiniteFloat, NonNegativeFloat, PositiveFloat, Seed

__all__ = [
    "MAX_RUBBLE_PIECES",
    "MAX_SHELF_ITEMS",
    "MAX_SHELF_LEVELS",
    "MODELS",
    "Object",
    "ObjectEntry",
    "ObjectModel",
]

# Limits on what sizes a world (every box is ray cast by every sensor): a shelf of 50 boards and
# 100 items per board is far beyond a real one; a heap of 100,000 pieces is ten times the largest
# rubble scene.
MAX_SHELF_LEVELS = 50
MAX_SHELF_ITEMS = 100
MAX_RUBBLE_PIECES = 100_000

XY = tuple[FiniteFloat, FiniteFloat]
Size2 = tuple[PositiveFloat, PositiveFloat]


class ObjectModel(FileModel):
    """What every object has: its type, an optional label and the variant it belongs to."""

    id: str | None = None
    only_in: Literal["teach", "playback"] | None = None

    @property
    def box_count(self) -> int:
        return 1


class Wall(ObjectModel):
    """A wall (or partition) standing from ``from`` to ``to``; ``thickness`` centred on it."""

    type: Literal["wall", "partition"]
    start: XY = Field(alias="from")
    to: XY
    height: PositiveFloat = 2.5
    thickness: PositiveFloat = 0.1
    z: FiniteFloat = 0.0

    @model_validator(mode="after")
    def _apart(self) -> Wall:
        if self.start == self.to:
            raise ValueError("'from' and 'to' must differ")
        return self


class Box(ObjectModel):
    """A box: ``center`` [x, y] stands it on the floor, [x, y, z] places its centre."""

    type: Literal["box"]
    center: Annotated[list[FiniteFloat], Field(min_length=2, max_length=3)]
    size: tuple[PositiveFloat, PositiveFloat, PositiveFloat]
    yaw: FiniteFloat = 0.0
    pitch: FiniteFloat = 0.0
    roll: FiniteFloat = 0.0


class Workbench(ObjectModel):
    """A top on four legs; ``size`` [length, width] of the top."""

    type: Literal["workbench"]
    center: XY
    size: Size2
    height: Annotated[float, Field(strict=True, gt=0, le=1.5, allow_inf_nan=False)] = 0.85
    top_thickness: PositiveFloat = 0.04
    leg: PositiveFloat = 0.05
    yaw: FiniteFloat = 0.0

    @model_validator(mode="after")
    def _proportions(self) -> Workbench:
        if self.top_thickness >= self.height:
            raise ValueError(
                f"top_thickness {self.top_thickness:g} m must be below the height {self.height:g} m"
            )
        if 2 * self.leg >= min(self.size):
            raise ValueError(f"two legs of {self.leg:g} m must fit in the size {list(self.size)}")
        return self


class Shelf(ObjectModel):
    """Four posts, ``levels`` boards and ``items`` random boxes on each board but the top one
    (on the only board when there is one), seeded."""

    type: Literal["shelf"]
    center: XY
    size: Size2
    height: PositiveFloat = 1.8
    levels: Annotated[int, Field(strict=True, ge=1, le=MAX_SHELF_LEVELS)] = 4
    items: Annotated[int, Field(strict=True, ge=0, le=MAX_SHELF_ITEMS)] = 0
    post: PositiveFloat = 0.04
    yaw: FiniteFloat = 0.0
    seed: Seed = 0

    @property
    def item_levels(self) -> int:
        return 1 if self.levels == 1 else self.levels - 1

    @property
    def box_count(self) -> int:
        return 4 + self.levels + self.items * self.item_levels


class Slope(ObjectModel):
    """A ramp rising by ``rise`` over its ``size`` [length, width]."""

    type: Literal["slope"]
    center: XY
    size: Size2
    rise: PositiveFloat
    thickness: PositiveFloat = 0.05
    yaw: FiniteFloat = 0.0


class Rubble(ObjectModel):
    """A heap of ``count`` slabs and blocks within ``radius``: random sizes and tilts, seeded."""

    type: Literal["rubble"]
    center: XY
    radius: PositiveFloat
    count: Annotated[int, Field(strict=True, ge=1, le=MAX_RUBBLE_PIECES)] = 20
    seed: Seed = 0
    size_range: Size2 = (0.1, 0.6)
    max_tilt: NonNegativeFloat = 30.0

    @model_validator(mode="after")
    def _range(self) -> Rubble:
        if self.size_range[0] > self.size_range[1]:
            raise ValueError(f"size_range must be [min, max], got {list(self.size_range)}")
        return self

    @property
    def box_count(self) -> int:
        return self.count


class Beam(ObjectModel):
    """A horizontal beam from ``from`` to ``to`` at height ``z``; ``size`` [width, height]."""

    type: Literal["beam"]
    start: XY = Field(alias="from")
    to: XY
    size: Size2
    z: FiniteFloat


class Pillar(ObjectModel):
    """An upright block; ``size`` [x, y] of its cross-section."""

    type: Literal["pillar"]
    center: XY
    size: Size2
    height: PositiveFloat = 2.5
    yaw: FiniteFloat = 0.0


MODELS: dict[str, type[ObjectModel]] = {
    "wall": Wall,
    "partition": Wall,
    "box": Box,
    "workbench": Workbench,
    "shelf": Shelf,
    "slope": Slope,
    "rubble": Rubble,
    "beam": Beam,
    "pillar": Pillar,
}


def _object(value: Any) -> ObjectModel:
    # picks the model by `type` so that errors show the document's path (objects[3].levels),
    # not the union member's name as pydantic's tagged unions do
    if isinstance(value, ObjectModel):
        return value
    if not isinstance(value, dict):
        raise ValueError(f"must be a mapping with a type ({', '.join(sorted(MODELS))})")
    kind = value.get("type")
    if not isinstance(kind, str) or kind not in MODELS:  # a list is not hashable
        raise ValueError(f"unknown type {kind!r} (known: {', '.join(sorted(MODELS))})")
    return MODELS[kind].model_validate(value)


Object = Annotated[ObjectModel, PlainValidator(_object)]
"""One entry of ``objects:``, checked by the model of its type."""


class ObjectEntry(RootModel[Object]):
    """One object alone (``parse(ObjectEntry, spec, path, at=("objects", 3)).root``)."""
