# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's ray space observation model against a brute-force numpy version of its equations
(rays marched in millimetre steps, distances to every occupied cell), and what it is for: an
object the map does not hold costs little, seeing through a wall costs much, and the model is
not blind along a corridor as the thesis' model is."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki import _core
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid

SIGMA, Z_HIT, Z_RAND, Z_INTRUSION, LAMBDA, MAX_DISTANCE = 0.2, 0.95, 0.05, 0.95, 0.1, 2.0
MAX_RANGE = 12.0
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 37)


def building() -> OccupancyGrid:
    """A 10 m x 6 m floor at 0.1 m: outer walls, an inner wall with a door, a pillar, and an
    unknown patch (unknown cells stop neither the model's rays nor the reference's)."""
    cells = np.zeros((60, 100), np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    cells[:, 55] = 100
    cells[25:35, 55] = 0  # a door
    cells[12:16, 20:24] = 100  # a pillar
    cells[40:50, 70:80] = -1
    return OccupancyGrid(cells, 0.1, Pose2(-1.0, -0.5, 0.0))


def reference_log_likelihood(grid: OccupancyGrid, pose, ranges) -> tuple[float, float]:
    """The model's equations beam by beam, by brute force. Returns the lowest and highest sum
    over the readings where the marched first-wall range is within 5 mm of the reading (there a
    millimetre decides whether the beam penetrates; both branches are allowed)."""
    res, ox, oy = grid.resolution, grid.origin.x, grid.origin.y
    occupied = np.argwhere(grid.cells >= 65)  # (row, col)
    centres = np.column_stack(
        [ox + (occupied[:, 1] + 0.5) * res, oy + (occupied[:, 0] + 0.5) * res]
    )
    x, y, theta = pose
    low = high = 0.0
    steps = np.arange(0.0, MAX_RANGE + 1e-3, 1e-3)
    for angle, r in zip(ANGLES, ranges, strict=True):
        if not (0 < r < MAX_RANGE):
            continue  # no return: skipped
        heading = theta + angle
        px, py = x + steps * math.cos(heading), y + steps * math.sin(heading)
        cx, cy = np.floor((px - ox) / res).astype(int), np.floor((py - oy) / res).astype(int)
        inside = (cx >= 0) & (cx < grid.width) & (cy >= 0) & (cy < grid.height)
        wall = np.zeros_like(inside)
        wall[inside] = grid.cells[cy[inside], cx[inside]] >= 65
        first = math.inf
        if wall.any():  # the exact entry into the first wall cell met: its later boundary
            k = int(np.argmax(wall))
            c, s = math.cos(heading), math.sin(heading)
            x0, y0 = ox + cx[k] * res, oy + cy[k] * res
            tx = ((x0 if c > 0 else x0 + res) - x) / c if c != 0 else -math.inf
            ty = ((y0 if s > 0 else y0 + res) - y) / s if s != 0 else -math.inf
            first = max(tx, ty)
        r_hat = min(first, r)
        ex, ey = x + r * math.cos(heading), y + r * math.sin(heading)
        gx, gy = math.floor((ex - ox) / res), math.floor((ey - oy) / res)
        if 0 <= gx < grid.width and 0 <= gy < grid.height:
            centre = (ox + (gx + 0.5) * res, oy + (gy + 0.5) * res)
            d = min(float(np.min(np.hypot(*(centres - centre).T))), MAX_DISTANCE)
        else:
            d = MAX_DISTANCE

        def pz(delta, r=r, d=d):
            h = max(d, delta)
            p = Z_HIT * math.exp(-h * h / (2 * SIGMA**2)) / (math.sqrt(2 * math.pi) * SIGMA)
            if delta <= 0:
                p += Z_INTRUSION * LAMBDA * math.exp(-LAMBDA * r)
            return p + Z_RAND / MAX_RANGE

        values = [math.log(pz(max(0.0, r - r_hat)))]
        if abs(first - r) < 5e-3:  # a millimetre decides: both branches
            values += [math.log(pz(0.0)), math.log(pz(max(0.0, r - first + 5e-3)))]
        low += min(values)
        high += max(values)
    return low, high


def model_for(grid: OccupancyGrid, **kw) -> _core.RaySpaceObservationModel:
    return _core.RaySpaceObservationModel(grid, **kw)


def test_cpp_equals_a_brute_force_numpy_version():
    grid = building()
    rng = np.random.default_rng(7)
    truth = (2.0, 2.0, 0.3)
    ranges = grid.cast_scans(np.array([truth]), ANGLES, max_range=MAX_RANGE)[0]
    # readings off the map's walls both ways (penetrating and short), some no-returns
    ranges = ranges + rng.uniform(-0.4, 0.4, ranges.size)
    ranges[::9] = MAX_RANGE
    model = model_for(grid)
    model.set_scan(ANGLES, ranges.astype(np.float32), MAX_RANGE)
    poses = np.column_stack(
        [rng.uniform(-0.5, 8.5, 15), rng.uniform(0.0, 5.0, 15), rng.uniform(-np.pi, np.pi, 15)]
    )
    poses = np.vstack([truth, poses, [[20.0, 20.0, 0.0]]])  # the last far off the map
    got = model.log_likelihoods(poses)
    for pose, value in zip(poses, got, strict=True):
        low, high = reference_log_likelihood(grid, pose, ranges.astype(np.float32))
        assert low - 1e-6 <= value <= high + 1e-6, (pose, value, low, high)
    assert model.readings == int(np.sum(ranges < MAX_RANGE))


def test_beam_probability_is_the_printed_mixture():
    model = model_for(building())
    model.set_scan(ANGLES, np.full(ANGLES.size, 3.0, np.float32), MAX_RANGE)
    g = Z_HIT / (math.sqrt(2 * math.pi) * SIGMA)
    short = Z_INTRUSION * LAMBDA * math.exp(-LAMBDA * 3.0)
    rand = Z_RAND / MAX_RANGE
    assert model.beam_probability(3.0, 0.0, 0.0) == pytest.approx(g + short + rand, rel=1e-12)
    # a penetrating beam has no intrusion term and is scored by its depth past the wall
    deep = g * math.exp(-(0.3**2) / (2 * SIGMA**2)) + rand
    assert model.beam_probability(3.0, 0.3, 0.1) == pytest.approx(deep, rel=1e-12)
    # stopping 2 m short of any wall is 10 times likelier than passing 1 m through one
    assert model.beam_probability(3.0, 0.0, 2.0) > 10 * model.beam_probability(3.0, 1.0, 1.0)


def corridor(length_cells: int = 300) -> OccupancyGrid:
    """A corridor 2 m wide at 0.1 m (30 m long by default), closed at both ends."""
    cells = np.zeros((22, length_cells), np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    return OccupancyGrid(cells, 0.1, Pose2(0.0, -1.1, 0.0))


def along_corridor_scores(model, xs) -> np.ndarray:
    return model.log_likelihoods(np.column_stack([xs, np.zeros_like(xs), np.zeros_like(xs)]))


def test_not_blind_along_a_corridor_where_the_thesis_model_is():
    """8 m from the corridor's end wall (beyond the thesis' 4 m window), a pose 1 m along the
    corridor must score clearly worse than the truth; the thesis' model cannot tell them apart."""
    grid = corridor()
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    truth = np.array([[21.9, 0.0, 0.0]])
    ranges = grid.cast_scans(truth, angles, max_range=MAX_RANGE)[0].astype(np.float32)
    ray = model_for(grid)
    ray.set_scan(angles, ranges, MAX_RANGE)
    scores = along_corridor_scores(ray, np.array([21.9, 20.9, 22.9]))
    assert scores[0] - max(scores[1:]) > math.log(1e6)
    builder = _core.LocalMapBuilder(8.0, 0.1)
    builder.add_scan(Pose2(), angles, ranges, MAX_RANGE)
    thesis = _core.SpaceObservationModel(grid)
    thesis.set_local_map(builder.build())
    blind = thesis.log_likelihoods(np.array([[21.9, 0.0, 0.0], [20.9, 0.0, 0.0]]))
    assert abs(blind[0] - blind[1]) < math.log(10.0)


def test_an_unmapped_object_costs_less_than_in_the_likelihood_field():
    """An object 1.5 m ahead that the map does not hold cuts some of the beams that would have
    met the end wall 5 m ahead: the truth stays the best pose along the corridor, and its score
    falls by at most 3/4 of the field's drop (intrusion is cheap: a cut beam ending 1.5 m ahead
    in the open costs log(1.9 / 0.086) = 3.1 nats here against the field's log(1.9 / 0.004) =
    6.2; the cut beams that end near a side wall cost the two models alike)."""
    grid = corridor(200)
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    truth = np.array([[15.0, 0.0, 0.0]])
    with_box = grid.cells.copy()
    with_box[14:20, 165:169] = 100  # 0.6 m x 0.4 m, 1.5 m ahead, left of the centre line
    seen = OccupancyGrid(with_box, 0.1, grid.origin)
    ranges = seen.cast_scans(truth, angles, max_range=MAX_RANGE)[0].astype(np.float32)
    clear = grid.cast_scans(truth, angles, max_range=MAX_RANGE)[0].astype(np.float32)
    xs = np.linspace(13.0, 17.0, 41)
    ray, field = model_for(grid), _core.LikelihoodFieldModel(grid)
    drops = {}
    for name, model in (("ray", ray), ("field", field)):
        model.set_scan(angles, clear, MAX_RANGE)
        before = model.log_likelihoods(truth)[0]
        model.set_scan(angles, ranges, MAX_RANGE)
        scores = along_corridor_scores(model, xs)
        drops[name] = before - model.log_likelihoods(truth)[0]
        if name == "ray":
            assert abs(xs[np.argmax(scores)] - 15.0) < 0.05
    assert 0 < drops["ray"] < 0.75 * drops["field"]


@pytest.mark.parametrize(
    ("kw", "needle"),
    [
        ({"sigma_hit": 0.0}, "sigma_hit"),
        ({"z_rand": 0.0}, "z_rand"),
        ({"z_intrusion": -1.0}, "z_intrusion"),
        ({"lambda_short": math.nan}, "lambda_short"),
        ({"max_beams": -1}, "max_beams"),
    ],
)
def test_bad_parameters_are_refused(kw, needle):
    with pytest.raises(ValueError, match=needle):
        model_for(building(), **kw)


def test_a_pose_before_any_scan_is_refused():
    with pytest.raises(RuntimeError, match="set a scan first"):
        model_for(building()).log_likelihoods(np.zeros((1, 3)))
