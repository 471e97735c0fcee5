# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The models of a scene file's robots and sensors: the ``robot`` mapping and each entry of the
``sensors`` list (or, with several robots, the same keys of each entry of ``robots``). Checked
by kiseki.sim.setup with kiseki._support.schema.parse before the robots and sensors are built, so an
error names the file, the path (``robots[1].sensors[0].rate_hz``) and the value.

A robot: ``type`` (diff_drive, the default, or omni), ``start`` [x, y, yaw_deg], ``params`` and
``odometry_errors`` (the parameter classes of kiseki.sim.robot_params for that type).

A sensor: ``type``, ``name``, ``mount`` [x, y, z] or [x, y, z, yaw_deg], ``pitch`` and ``roll``
(deg, the mount's rotation Rz(yaw) Ry(pitch) Rx(roll)),
``rate_hz`` (at most :data:`MAX_RATE_HZ`), ``params`` (the parameter class of kiseki.sim.sensors
or kiseki.sim.tilting_laser for that type), and the keys of its type only: ``preset`` (laser),
``width``/``height`` (depth_camera), ``arm`` (magnetometer), ``targets`` (bearing). A key of
another type is an unknown key.

:func:`check_robots` checks every robot and sensor of a scene when the scene is loaded
(kiseki.sim.scene_schema.SceneDoc), with the rules that depend on the rest of the scene: at most
:data:`MAX_SENSORS` sensors per robot, unique sensor names, a magnetometer only in a scene with
a ``magnetic`` section, bearing targets among the scene's other robots. Where the mount must lie
(on the robot) and one bar per arm pivot are checked by kiseki.sim.setup when it builds them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Annotated, Any, Literal, TypeVar

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)
from pydantic_core import PydanticCustomError

from kiseki._support.schema import FileModel, FiniteFloat
from kiseki.sim.robot_params import (
    DiffDriveParams,
    OdometryErrorParams,
    OmniOdometryErrorParams,
    OmniParams,
)
from kiseki.sim.sensors import (
    LASER_PRESETS,
    BearingParams,
    DepthCameraParams,
    ImageSide,
    LaserParams,
)
from kiseki.sim.tilting_laser import TiltingLaserParams

__all__ = [
    "DEFAULT_MOUNT",
    "MAX_RATE_HZ",
    "MAX_SENSORS",
    "ROBOT_MODELS",
    "SENSOR_MODELS",
    "RobotKind",
    "RobotSections",
    "SensorKind",
    "check_robots",
]

MAX_RATE_HZ = 1000.0
"""Readings per second of one sensor."""
MAX_SENSORS = 50
"""Sensors on one robot (each is read, and a camera rendered, every period)."""
DEFAULT_MOUNT = (0.0, 0.0, 0.5)

Start = Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)]
MountValues = Annotated[list[FiniteFloat], Field(min_length=3, max_length=4)]
Rate = Annotated[float, Field(strict=True, gt=0, le=MAX_RATE_HZ, allow_inf_nan=False)]
Name = Annotated[str, Field(strict=True, min_length=1)]


def _empty_is_default(value: Any) -> Any:
    """``params:`` with nothing after it (YAML null) keeps the defaults."""
    return {} if value is None else value


Section = BeforeValidator(_empty_is_default)


class _Kind(FileModel):
    """The ``type`` of an entry, read first to choose the entry's model (other keys ignored)."""

    model_config = ConfigDict(extra="ignore", frozen=True)


class RobotKind(_Kind):
    type: Annotated[str, Field(strict=True)] = "diff_drive"

    @field_validator("type")
    @classmethod
    def _known(cls, value: str) -> str:
        if value not in ROBOT_MODELS:
            raise ValueError(f"must be {' or '.join(ROBOT_MODELS)}")
        return value


class SensorKind(_Kind):
    type: Annotated[str, Field(strict=True)]

    @field_validator("type")
    @classmethod
    def _known(cls, value: str) -> str:
        if value not in SENSOR_MODELS:
            raise ValueError(f"unknown sensor type, must be one of {', '.join(SENSOR_MODELS)}")
        return value


# ------------------------------------------------------------------------------------- robots


class DiffDriveSpec(FileModel):
    type: Literal["diff_drive"] = "diff_drive"
    start: Start = [0.0, 0.0, 0.0]
    params: Annotated[DiffDriveParams, Section] = DiffDriveParams()
    odometry_errors: Annotated[OdometryErrorParams, Section] = OdometryErrorParams()


class OmniSpec(FileModel):
    type: Literal["omni"]
    start: Start = [0.0, 0.0, 0.0]
    params: Annotated[OmniParams, Section] = OmniParams()
    odometry_errors: Annotated[OmniOdometryErrorParams, Section] = OmniOdometryErrorParams()


ROBOT_MODELS: dict[str, type[DiffDriveSpec | OmniSpec]] = {
    "diff_drive": DiffDriveSpec,
    "omni": OmniSpec,
}

# ------------------------------------------------------------------------------------ sensors


class _Sensor(FileModel):
    """The keys every sensor takes."""

    name: Name | None = None
    mount: MountValues = list(DEFAULT_MOUNT)
    pitch: FiniteFloat = 0.0
    roll: FiniteFloat = 0.0
    rate_hz: Rate | None = None


class LaserSpec(_Sensor):
    type: Literal["laser"]
    preset: Annotated[str, Field(strict=True)] = "hokuyo_utm30lx"
    params: LaserParams | None = None  # the preset's, with the keys given here changed

    @model_validator(mode="before")
    @classmethod
    def _preset_params(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        preset = LASER_PRESETS.get(data.get("preset", "hokuyo_utm30lx"))  # type: ignore[arg-type]
        params = _empty_is_default(data.get("params"))
        if preset is not None and isinstance(params, dict):
            return {**data, "params": {**dataclasses.asdict(preset), **params}}
        return data

    @field_validator("preset")
    @classmethod
    def _known_preset(cls, value: str) -> str:
        if value not in LASER_PRESETS:
            raise ValueError(f"must be one of {', '.join(LASER_PRESETS)}")
        return value


class DepthCameraSpec(_Sensor):
    type: Literal["depth_camera"]
    width: ImageSide | None = None  # the image size, instead of params.width/height
    height: ImageSide | None = None
    params: Annotated[DepthCameraParams, Section] = DepthCameraParams()

    @model_validator(mode="before")
    @classmethod
    def _size_once(cls, data: Any) -> Any:
        params = data.get("params") if isinstance(data, dict) else None
        for key in ("width", "height"):
            if isinstance(params, dict) and key in data and key in params:
                raise ValueError(f"give {key} once: at the sensor or in its params")
        return data

    @model_validator(mode="after")
    def _image_size(self) -> DepthCameraSpec:
        native = self.params.native_width
        if self.width is not None and self.width > native:
            raise ValueError(f"width {self.width} must be at most params.native_width {native}")
        return self

    @property
    def camera(self) -> DepthCameraParams:
        """The camera's parameters with the sensor's ``width``/``height``."""
        size = {k: getattr(self, k) for k in ("width", "height") if getattr(self, k) is not None}
        return dataclasses.replace(self.params, **size)


class MagnetometerSpec(_Sensor):
    type: Literal["magnetometer"]
    # keyword arguments of kiseki.sim.magnetic.Magnetometer / the arm, checked there
    params: Annotated[dict[str, Any], Section] = {}
    arm: dict[str, Any] | None = None  # kiseki.sim.magnetic_arm checks it


class BearingSpec(_Sensor):
    type: Literal["bearing"]
    targets: Annotated[list[Name], Field(min_length=1)] | None = None  # default: all others
    params: Annotated[BearingParams, Section] = BearingParams()


class TiltingLaserSpec(_Sensor):
    type: Literal["tilting_laser"]
    params: Annotated[TiltingLaserParams, Section] = TiltingLaserParams()


SENSOR_MODELS: dict[str, type[_Sensor]] = {
    "laser": LaserSpec,
    "depth_camera": DepthCameraSpec,
    "magnetometer": MagnetometerSpec,
    "bearing": BearingSpec,
    "tilting_laser": TiltingLaserSpec,
}


# ------------------------------------------------------------------- a scene's robots at load

_M = TypeVar("_M", bound=BaseModel)
Loc = tuple[str | int, ...]


def _at(loc: Loc, value: Any, message: str, kind: str = "value_error") -> dict:
    return {
        "type": PydanticCustomError(kind, "{message}", {"message": message}),
        "loc": loc,
        "input": value,
    }


def _checked(model: type[_M], data: Any, at: Loc) -> _M:
    """``data`` checked by ``model``; its errors placed at ``at`` in the scene file."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        errors = [
            _at((*at, *e["loc"]), e.get("input"), e["msg"], e["type"])
            for e in exc.errors(include_url=False)
        ]
        raise ValidationError.from_exception_data("scene", errors) from None


def _fail(at: Loc, value: Any, message: str) -> ValidationError:
    return ValidationError.from_exception_data("scene", [_at(at, value, message)])


@dataclasses.dataclass(frozen=True)
class RobotSections:
    """One robot of a scene file as it is written: its name, where its keys are (``robot``
    or ``robots[i]``), its robot keys (type, start, params, odometry_errors) and where its
    sensors are (``sensors`` or ``robots[i].sensors``)."""

    name: str
    at: Loc
    robot: dict
    sensors_at: Loc
    sensors: Sequence[Any]


def check_robots(robots: Sequence[RobotSections], magnetic: bool) -> None:
    """Every robot's and sensor's section checked by its model, and the rules that depend on the
    rest of the scene (``magnetic``: the scene has a magnetic section); a pydantic
    ValidationError at the section's place in the file otherwise."""
    names = {r.name for r in robots}
    for r in robots:
        kind = _checked(RobotKind, r.robot, r.at).type
        _checked(ROBOT_MODELS[kind], r.robot, r.at)
        if len(r.sensors) > MAX_SENSORS:
            raise _fail(r.sensors_at, len(r.sensors), f"at most {MAX_SENSORS} sensors per robot")
        others = sorted(names - {r.name})
        sensor_names = []
        for i, raw in enumerate(r.sensors):
            at = (*r.sensors_at, i)
            spec = _checked(SENSOR_MODELS[_checked(SensorKind, raw, at).type], raw, at)
            sensor_names.append(spec.name if spec.name is not None else f"sensor{i}")
            if isinstance(spec, MagnetometerSpec) and not magnetic:
                raise _fail(at, raw, "a magnetometer needs the scene's 'magnetic' section")
            if isinstance(spec, BearingSpec):
                targets = list(spec.targets or others)
                if not targets or not set(targets) <= set(others):
                    raise _fail(
                        (*at, "targets"),
                        targets,
                        f"must be other robots of the scene ({', '.join(others) or 'none'})",
                    )
        if len(set(sensor_names)) != len(sensor_names):
            raise _fail(r.sensors_at, sensor_names, "sensor names must be unique")
