# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The models of the occupancy-map settings kiseki reads:

- :class:`RosMapYaml`, a ROS map_server map YAML file (nav2's fields)::

      image: map.pgm              # the image, beside the YAML file (or an absolute path)
      resolution: 0.05            # m per cell (YAML 1.2 numbers: 5e-2 is a number)
      origin: [-10.0, -5.0, 0.0]  # x, y, yaw of the lower-left cell
      mode: trinary               # trinary, scale or raw (optional)
      negate: 0                   # 0 or 1, false or true (optional)
      occupied_thresh: 0.65       # in [0, 1] (optional)
      free_thresh: 0.196          # in [0, occupied_thresh] (optional)

- :class:`MapBuildSettings`, the parameters of :class:`kiseki.mapping.MapBuildConfig` given
  as a mapping (every key optional).

A problem is one line naming the file, the key and the value
(``map.yaml: resolution: must be greater than or equal to 0.0001, got -0.05``)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field, ValidationInfo, field_validator

from kiseki._support.schema import (
    MAGNITUDE_LIMIT,
    FileModel,
    FiniteFloat,
    NonNegativeFloat,
    PositiveFloat,
)

__all__ = ["MODES", "MapBuildSettings", "RosMapYaml"]

MODES = ("trinary", "scale", "raw")

Share = Annotated[float, Field(strict=True, ge=0, le=1, allow_inf_nan=False)]
# m per cell: from 0.1 mm (far finer than any range sensor resolves; 1e-300 was read as a
# map 3e-298 m across) up to kiseki's limit for any length
CellSize = Annotated[float, Field(strict=True, ge=1e-4, le=MAGNITUDE_LIMIT, allow_inf_nan=False)]
Probability = Annotated[float, Field(strict=True, gt=0, lt=1, allow_inf_nan=False)]


def _negate(value: Any) -> Any:
    if value in (0, 1) and isinstance(value, int):  # bool is an int: true / false too
        return bool(value)
    raise ValueError("must be 0 or 1 (or false / true)")


def _pose(value: Any) -> Any:
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ValueError("must be a list [x, y, yaw]")
    return value


class RosMapYaml(FileModel):
    """A ROS map YAML file, as nav2's map_server reads it."""

    image: Annotated[str, Field(strict=True, min_length=1, max_length=4096)]
    resolution: CellSize
    origin: Annotated[tuple[FiniteFloat, FiniteFloat, FiniteFloat], BeforeValidator(_pose)]
    mode: Literal["trinary", "scale", "raw"] = "trinary"
    negate: Annotated[bool, BeforeValidator(_negate)] = False
    occupied_thresh: Share = 0.65
    free_thresh: Share = 0.196

    @field_validator("free_thresh")
    @classmethod
    def _below_occupied(cls, value: float, info: ValidationInfo) -> float:
        occupied = info.data.get("occupied_thresh")
        if occupied is not None and value > occupied:
            raise ValueError(f"must not exceed occupied_thresh ({occupied:g})")
        return value


class MapBuildSettings(FileModel):
    """The parameters of map building (:class:`kiseki.mapping.MapBuildConfig`): every key is
    optional (unset keys keep the config's defaults, so the defaults here are never used and
    never checked: ``null`` is not a value); metres, probabilities in (0, 1)."""

    resolution: PositiveFloat = None  # type: ignore[assignment]
    usable_range: PositiveFloat = None  # type: ignore[assignment]
    min_range: NonNegativeFloat = None  # type: ignore[assignment]
    clear_on_no_return: Annotated[bool, Field(strict=True)] = None  # type: ignore[assignment]
    prob_hit: Probability = None  # type: ignore[assignment]
    prob_miss: Probability = None  # type: ignore[assignment]
    clamp_min: Probability = None  # type: ignore[assignment]
    clamp_max: Probability = None  # type: ignore[assignment]
    occupied_thresh: Share = None  # type: ignore[assignment]
    free_thresh: Share = None  # type: ignore[assignment]
    margin: NonNegativeFloat = None  # type: ignore[assignment]
