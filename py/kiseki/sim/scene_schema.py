# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a scene file's top level (see :mod:`kiseki.sim.scene` for what each key means),
checked by :mod:`kiseki._support.schema`: name, description, source, bounds, floor, octomap, objects
(:mod:`kiseki.sim.primitives_schema`), grid_resolution, measurement_grid, robots (their name
and the sections kiseki.sim.setup and kiseki.sim.robot_params read), turns, poses, pedestrians and
point_robots, ``calibrated`` (:class:`Calibration`: the parameters fitted to a paper's number;
each path is checked by :mod:`kiseki.sim.calibration`),
and ``route`` (:class:`Route`, ``route: {}`` is none). ``robot``, ``sensors`` and
each robot's ``type``, ``start``, ``params``, ``odometry_errors`` are checked by the models of
kiseki.sim.setup_schema (:func:`~kiseki.sim.setup_schema.check_robots`, with the rules that
depend on the rest of the scene), ``magnetic`` by kiseki.sim.magnetic_schema (in
kiseki.sim.scene.load_scene).

Limits on what sizes a run: the boxes the objects expand to (every box is ray cast by every
sensor: 200,000 boxes take about 12 s to build), the ground truth's cells
(kiseki.mapping.check_map_size), the measurement grid's points
(kiseki.sim.magnetic_survey.MAX_GRID_POINTS), robots, pedestrians, turns' moves and poses.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

from pydantic import BeforeValidator, Field, field_validator, model_validator
from pydantic_core import PydanticCustomError, ValidationError

from kiseki._support.schema import FileModel, FiniteFloat, NonNegativeFloat, PositiveFloat
from kiseki.mapping import check_map_size
from kiseki.sim.magnetic_survey import MeasurementGrid
from kiseki.sim.primitives_schema import Object
from kiseki.sim.setup_schema import RobotSections, check_robots

__all__ = [
    "Calibration",
    "MAX_POSES",
    "MAX_PEDESTRIANS",
    "MAX_ROBOTS",
    "MAX_ROUTE_NAME_LENGTH",
    "MAX_ROUTE_POINTS",
    "MAX_SCENE_BOXES",
    "MAX_TURN_MOVES",
    "Route",
    "SceneDoc",
    "extent_problem",
]

MAX_SCENE_BOXES = 200_000  # the floor and every object's boxes
MAX_ROBOTS = 100  # each renders its sensors every step
MAX_PEDESTRIANS = 1_000  # each is stamped into every laser's grid every scan
MAX_TURN_MOVES = 10_000
MAX_POSES = 10_000
MAX_ROUTE_POINTS = 10_000  # as a waypoint file's marks (kiseki.teach.waypoint_schema)
MAX_ROUTE_NAME_LENGTH = 64  # as a waypoint file's names: teaching marks the named points

XY = tuple[FiniteFloat, FiniteFloat]
XYZ = tuple[FiniteFloat, FiniteFloat, FiniteFloat]
Name = Annotated[str, Field(strict=True, min_length=1)]
RouteName = Annotated[str, Field(strict=True, min_length=1, max_length=MAX_ROUTE_NAME_LENGTH)]


def fail(loc: tuple[str | int, ...], value: Any, message: str) -> ValidationError:
    """An error at ``loc`` (relative to the model that raises it), so that a check across
    fields still names the field it is about."""
    error = PydanticCustomError("value_error", "{message}", {"message": message})
    return ValidationError.from_exception_data(
        "scene", [{"type": error, "loc": loc, "input": value}]
    )


class Bounds(FileModel):
    min: XYZ
    max: XYZ

    @model_validator(mode="after")
    def _ordered(self) -> Bounds:
        if not all(b > a for a, b in zip(self.min, self.max, strict=True)):
            raise ValueError("max must exceed min in x, y and z")
        return self


class MeasurementGridDoc(FileModel):
    """``{lower: [x, y, z], upper: [x, y, z], spacing: m}`` (kiseki.sim.magnetic_survey)."""

    lower: XYZ
    upper: XYZ
    spacing: PositiveFloat

    @model_validator(mode="after")
    def _grid(self) -> MeasurementGridDoc:
        try:  # corners on the grid and the points' limit: the grid's own checks
            MeasurementGrid(self.lower, self.upper, self.spacing, where="")
        except ValueError as err:
            raise ValueError(str(err).removeprefix(": ")) from None
        return self


def _empty_is_none(value: Any) -> Any:
    """``route: {}`` is no route."""
    return None if value == {} else value


class Route(FileModel):
    """``{waypoints: [[x, y], ...], names: [NAME, ...], speed: m/s}``: the path a robot is
    driven along (pure pursuit, kiseki.control.PurePursuit) at ``speed`` (0.5 m/s when not
    given); ``names`` (one per waypoint) are the waypoints teaching marks, so they follow the
    waypoint file's rule for names (kiseki.teach.waypoint_schema: unique, 1 to 64 characters)."""

    waypoints: Annotated[list[XY], Field(min_length=2, max_length=MAX_ROUTE_POINTS)]
    names: list[RouteName] | None = None
    speed: Annotated[float, Field(strict=True, gt=0, le=5, allow_inf_nan=False)] = 0.5

    @field_validator("waypoints")
    @classmethod
    def _legs(cls, points: list[tuple[float, float]]) -> list[tuple[float, float]]:
        for i in range(1, len(points)):
            if points[i] == points[i - 1]:
                raise fail((i,), list(points[i]), "consecutive waypoints must differ")
        return points

    @field_validator("names")
    @classmethod
    def _unique_names(cls, names: list[str] | None) -> list[str] | None:
        for i, name in enumerate(names or []):
            if name in names[:i]:
                raise fail((i,), name, "waypoint names must be unique")
        return names

    @model_validator(mode="after")
    def _one_name_each(self) -> Route:
        if self.names is not None and len(self.names) != len(self.waypoints):
            raise fail(
                ("names",),
                self.names,
                f"must give one name per waypoint ({len(self.waypoints)})",
            )
        return self

    def as_dict(self) -> dict:
        """The route as kiseki.sim.scene.Scene holds it: waypoints as lists, names when given."""
        out: dict[str, Any] = {"waypoints": [list(p) for p in self.waypoints], "speed": self.speed}
        if self.names is not None:
            out["names"] = list(self.names)
        return out


RouteSection = Annotated[Route | None, BeforeValidator(_empty_is_none)]


class RobotEntry(FileModel):
    """One of ``robots``: its name; the rest is read by kiseki.sim.setup and
    kiseki.sim.robot_params."""

    name: Name
    type: Any = None
    start: Any = None
    params: Any = None
    odometry_errors: Any = None
    sensors: list[Any] | None = None
    route: RouteSection = None


class Move(FileModel):
    robot: Name
    to: XY


class Turns(FileModel):
    """``{goal: [x, y], speed: m/s, moves: [{robot: NAME, to: [x, y]}, ...]}``."""

    goal: XY
    speed: Annotated[float, Field(strict=True, gt=0, le=5, allow_inf_nan=False)] = 0.3
    moves: Annotated[list[Move], Field(min_length=1, max_length=MAX_TURN_MOVES)]

    @model_validator(mode="after")
    def _ends_on_goal(self) -> Turns:
        last = len(self.moves) - 1
        if math.dist(self.moves[last].to, self.goal) > 1e-9:
            raise fail(
                ("moves", last, "to"),
                list(self.moves[last].to),
                f"the last move must end on the goal {list(self.goal)}",
            )
        return self


class Poses(FileModel):
    """``{corner: [x, y], distance: m, phi_deg: [start, stop, step], heading_deg}``."""

    corner: XY
    distance: PositiveFloat
    phi_deg: tuple[FiniteFloat, FiniteFloat, FiniteFloat]
    heading_deg: FiniteFloat

    @field_validator("phi_deg")
    @classmethod
    def _sweep(cls, value: tuple[float, float, float]) -> tuple[float, float, float]:
        start, stop, step = value
        if step <= 0 or stop < start:
            raise ValueError("must be [start, stop, step] with step > 0 and stop >= start")
        if (stop - start) / step >= MAX_POSES:
            raise ValueError(f"must give at most {MAX_POSES:,} poses")
        return value

    @property
    def count(self) -> int:
        start, stop, step = self.phi_deg
        return int(math.floor((stop - start) / step + 1e-9)) + 1


class PedestrianDoc(FileModel):
    """``{name, radius, start: [x, y], velocity: [vx, vy], start_time, stop_after}``."""

    name: Name
    start: XY
    velocity: XY
    radius: PositiveFloat = 0.25
    start_time: NonNegativeFloat = 0.0
    stop_after: NonNegativeFloat | None = None


def _unique(items: list, what: str) -> None:
    names = [item.name for item in items]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise fail((i, "name"), name, f"{what} names must be unique")


def extent_problem(
    lo, hi, resolution: float, grid: MeasurementGridDoc | None
) -> tuple[str, Any, str] | None:
    """(field, value, problem) when the ground truth's cells or the measurement grid do not fit
    the bounds lo..hi; None when they do. Checked by :class:`SceneDoc` when the file gives its
    bounds, and by kiseki.sim.scene on the world's bounds when it does not."""
    try:  # the ground truth's cells: the map limits of kiseki.mapping
        check_map_size(hi[0] - lo[0], hi[1] - lo[1], resolution)
    except ValueError as err:
        return "grid_resolution", resolution, str(err)
    if grid is not None and (
        any(g < b for g, b in zip(grid.lower, lo, strict=True))
        or any(g > b for g, b in zip(grid.upper, hi, strict=True))
    ):
        return (
            "measurement_grid",
            {"lower": list(grid.lower), "upper": list(grid.upper)},
            f"leaves the scene's bounds {list(map(float, lo))}..{list(map(float, hi))}",
        )
    return None


class Calibration(FileModel):
    """A scene parameter fitted to a paper's number: ``parameter`` is its dotted key path in
    the scene file (``robots.0.odometry_errors.wheel_radius``), ``fitted_to`` the number it was
    fitted to (in ``unit``), ``source`` where the number is printed (paper, table or figure).
    No claim may then compare a result with that number (the experiments' calibration test)."""

    parameter: Name
    fitted_to: FiniteFloat
    unit: str = Field(strict=True)
    source: Name


class SceneDoc(FileModel):
    """A scene file's top level."""

    name: str | None = None
    description: str = ""
    source: str = ""
    bounds: Bounds | None = None
    floor: bool = Field(False, strict=True)
    octomap: str | None = None
    objects: list[Object] = []
    grid_resolution: PositiveFloat = 0.05
    robot: dict[str, Any] | None = None
    sensors: list[Any] | None = None
    route: RouteSection = None
    magnetic: dict[str, Any] | None = None
    measurement_grid: MeasurementGridDoc | None = None
    robots: Annotated[list[RobotEntry], Field(min_length=1, max_length=MAX_ROBOTS)] | None = None
    turns: Turns | None = None
    poses: Poses | None = None
    pedestrians: Annotated[list[PedestrianDoc], Field(max_length=MAX_PEDESTRIANS)] | None = None
    point_robots: bool = Field(False, strict=True)
    calibrated: list[Calibration] = []

    @field_validator("objects")
    @classmethod
    def _boxes(cls, objects: list) -> list:
        total = sum(o.box_count for o in objects)
        if total > MAX_SCENE_BOXES:
            raise ValueError(
                f"make {total:,} boxes, more than the limit of {MAX_SCENE_BOXES:,} boxes"
            )
        return objects

    @field_validator("robots")
    @classmethod
    def _robot_names(cls, robots: list[RobotEntry] | None) -> list[RobotEntry] | None:
        _unique(robots or [], "robot")
        return robots

    @field_validator("pedestrians")
    @classmethod
    def _pedestrian_names(cls, peds: list[PedestrianDoc] | None) -> list[PedestrianDoc] | None:
        _unique(peds or [], "pedestrian")
        return peds

    def robot_names(self) -> list[str]:
        return ["robot"] if self.robots is None else [r.name for r in self.robots]

    @model_validator(mode="after")
    def _together(self) -> SceneDoc:
        single = [k for k in ("robot", "sensors", "route") if getattr(self, k) is not None]
        if self.robots is not None and single:
            given = getattr(self, single[0])
            given = given.as_dict() if isinstance(given, Route) else given
            raise fail((single[0],), given, "give 'robots' or this, not both")
        if self.floor and self.bounds is None:
            raise fail(("floor",), True, "'floor: true' needs 'bounds'")
        if self.point_robots and self.robots is None:
            raise fail(("point_robots",), True, "applies only to a scene with 'robots'")
        if self.measurement_grid is not None and self.magnetic is None:
            grid = self.measurement_grid.model_dump()
            raise fail(("measurement_grid",), grid, "applies only to a scene with 'magnetic'")
        if self.turns is not None:
            routes = [self.route] if self.robots is None else [r.route for r in self.robots]
            if any(routes):
                given = [r.as_dict() if r else None for r in routes]
                raise fail(("turns",), given, "a scene with 'turns' gives its robots no routes")
            names = self.robot_names()
            for i, move in enumerate(self.turns.moves):
                if move.robot not in names:
                    raise fail(
                        ("turns", "moves", i, "robot"),
                        move.robot,
                        f"must be one of the scene's robots ({', '.join(names)})",
                    )
        if self.bounds is not None:
            problem = extent_problem(
                self.bounds.min, self.bounds.max, self.grid_resolution, self.measurement_grid
            )
            if problem is not None:
                raise fail((problem[0],), problem[1], problem[2])
        return self

    @model_validator(mode="after")
    def _robots_and_sensors(self) -> SceneDoc:
        if self.robots is None:
            robots = [
                RobotSections(
                    "robot", ("robot",), dict(self.robot or {}), ("sensors",), self.sensors or []
                )
            ]
        else:
            keys = ("type", "start", "params", "odometry_errors")
            robots = [
                RobotSections(
                    r.name,
                    ("robots", i),
                    {k: getattr(r, k) for k in keys if k in r.model_fields_set},
                    ("robots", i, "sensors"),
                    r.sensors or [],
                )
                for i, r in enumerate(self.robots)
            ]
        check_robots(robots, magnetic=bool(self.magnetic))
        return self
