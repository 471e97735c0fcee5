# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic world, magnetometer and bearing sensor: closed forms, frames, noise, validation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki import Pose2
from kiseki.sim.magnetic import (
    DEFAULT_DECLINATION_DEG,
    DEFAULT_EARTH_TOTAL,
    DEFAULT_INCLINATION_DEG,
    ROBOT_SOURCE_MOMENT,
    Dipole,
    DipoleLine,
    MagneticWorld,
    Magnetometer,
    default_earth_field,
    dipole_field,
    earth_field_from_angles,
    magnetic_azimuth,
    robot_self_sources,
)

MU0 = 4e-7 * math.pi  # T m / A
TESLA_TO_GAUSS = 1e4


def quiet_world(**kwargs) -> MagneticWorld:
    """A world with the default Earth field and no drift."""
    kwargs.setdefault("drift_amplitude", 0.0)
    return MagneticWorld(**kwargs)


def magnetic_north_heading(world: MagneticWorld) -> float:
    """World heading (CCW from +x = east) of the horizontal Earth field."""
    return math.atan2(world.earth_field[1], world.earth_field[0])


# ---------------------------------------------------------------------------------- dipoles


def test_dipole_on_axis_and_equatorial_closed_forms():
    m, r = 2.5, 0.7
    d = Dipole((1.0, -2.0, 0.5), (0.0, 0.0, m))
    axial = d.field_at((1.0, -2.0, 0.5 + r))
    equatorial = d.field_at((1.0 + r, -2.0, 0.5))
    expect_axial = 2 * MU0 * m / (4 * math.pi * r**3) * TESLA_TO_GAUSS
    expect_equatorial = -MU0 * m / (4 * math.pi * r**3) * TESLA_TO_GAUSS
    np.testing.assert_allclose(axial, [0, 0, expect_axial], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(equatorial, [0, 0, expect_equatorial], rtol=1e-12, atol=1e-15)


def test_dipole_field_equals_curl_of_vector_potential():
    # B = curl A, A = mu0/(4 pi) m x r / |r|^3: an independent route to the closed form
    moment = np.array([0.3, -1.2, 0.8])
    centre = np.array([0.2, 0.1, -0.3])

    def potential(p):
        r = p - centre
        return MU0 / (4 * math.pi) * np.cross(moment, r) / np.linalg.norm(r) ** 3

    d = Dipole(centre, moment)
    rng = np.random.default_rng(4)
    h = 1e-6
    for _ in range(5):
        p = centre + rng.uniform(0.2, 1.0, 3) * rng.choice([-1, 1], 3)
        jac = np.empty((3, 3))  # jac[i, j] = dA_i / dx_j
        for j in range(3):
            e = np.zeros(3)
            e[j] = h
            jac[:, j] = (potential(p + e) - potential(p - e)) / (2 * h)
        curl = np.array([jac[2, 1] - jac[1, 2], jac[0, 2] - jac[2, 0], jac[1, 0] - jac[0, 1]])
        np.testing.assert_allclose(d.field_at(p), curl * TESLA_TO_GAUSS, rtol=1e-6)


def test_dipole_field_decays_as_inverse_cube():
    d = Dipole((0, 0, 0), (0.4, 0.9, -0.2))
    direction = np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
    for r in (0.3, 1.0, 2.5):
        near = d.field_at(r * direction)
        far = d.field_at(2 * r * direction)
        np.testing.assert_allclose(far, near / 8, rtol=1e-12)


def test_dipole_inside_radius_is_bounded_uniform_sphere_field():
    m, radius = 1.5, 0.05
    d = Dipole((0, 0, 0), (0, 0, m), radius)
    inside = 2e-3 * m / radius**3
    for p in [(0, 0, 0), (0.01, 0, 0), (0, 0.02, -0.03)]:
        np.testing.assert_allclose(d.field_at(p), [0, 0, inside], rtol=1e-12)
    # equals the on-axis outside field at the surface
    np.testing.assert_allclose(d.field_at((0, 0, radius * (1 + 1e-9))), [0, 0, inside], rtol=1e-8)


def test_dipole_line_equals_sum_of_its_dipoles():
    start, end = np.array([0.0, 0.0, -0.8]), np.array([3.0, 0.4, -0.8])
    mpm, spacing = np.array([0.0, 0.5, -2.0]), 0.25
    line = DipoleLine(start, end, mpm, spacing)
    length = np.linalg.norm(end - start)
    n = round(length / spacing)
    assert len(line.positions) == n == 12
    dipoles = [
        Dipole(start + (i + 0.5) / n * (end - start), mpm * length / n, spacing / 2)
        for i in range(n)
    ]
    pts = np.random.default_rng(7).uniform([-1, -1, 0], [4, 1, 1], (50, 3))
    expected = sum(d.field_at(pts) for d in dipoles)
    np.testing.assert_allclose(line.field_at(pts), expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(line.moments.sum(axis=0), mpm * length, rtol=1e-12)


def test_dipole_field_function_chunks_consistently():
    rng = np.random.default_rng(2)
    pos, mom = rng.uniform(-5, 5, (400, 3)), rng.normal(0, 1, (400, 3))
    pts = rng.uniform(-5, 5, (3000, 3))  # > one block of the (points x dipoles) loop
    full = dipole_field(pts, pos, mom, 0.05)
    one_by_one = sum(dipole_field(pts, p, m, 0.05) for p, m in zip(pos[:3], mom[:3], strict=True))
    np.testing.assert_allclose(
        full, one_by_one + dipole_field(pts, pos[3:], mom[3:], 0.05), rtol=1e-9, atol=1e-12
    )
    np.testing.assert_allclose(full[2500:], dipole_field(pts[2500:], pos, mom, 0.05), rtol=1e-12)


# ------------------------------------------------------------------------------- the world


def test_default_earth_field_magnitude_inclination_declination():
    b = default_earth_field()
    total = np.linalg.norm(b)
    horizontal = math.hypot(b[0], b[1])
    assert total == pytest.approx(0.465, abs=1e-12)  # 46.5 uT
    assert 0.44 < total < 0.49  # Japan, about 46 uT
    assert math.degrees(math.atan2(-b[2], horizontal)) == pytest.approx(49.5, abs=1e-9)
    assert math.degrees(math.atan2(b[0], b[1])) == pytest.approx(-7.5, abs=1e-9)  # west of N
    assert b[2] < 0  # points down in the northern hemisphere (world z up)
    np.testing.assert_allclose(MagneticWorld().earth_field, b)
    np.testing.assert_allclose(
        earth_field_from_angles(
            DEFAULT_EARTH_TOTAL, DEFAULT_INCLINATION_DEG, DEFAULT_DECLINATION_DEG
        ),
        b,
    )


def test_field_at_vectorised_equals_point_by_point():
    world = MagneticWorld(
        dipoles=[Dipole((1, 2, -0.5), (0, 3, -4)), Dipole((-2, 0, -1), (5, 0, 0), 0.1)],
        lines=[DipoleLine((0, -3, -0.6), (0, 3, -0.6), (1, 0, -1), 0.2)],
        gradient=[[0, 0, 0], [0, 0, 0.01], [0, 0.01, 0]],
        gradient_origin=(0.5, 0.5, 0),
        drift_amplitude=0.01,
        drift_period=600.0,
    )
    rng = np.random.default_rng(3)
    pts = rng.uniform(-3, 3, (40, 3))
    times = rng.uniform(0, 1000, 40)
    together = world.field_at(pts, times)
    assert together.shape == (40, 3)
    for p, t, b in zip(pts, times, together, strict=True):
        np.testing.assert_allclose(world.field_at(p, t), b, rtol=1e-12, atol=1e-15)
    # a scalar time is broadcast to every point
    np.testing.assert_allclose(world.field_at(pts, 5.0), world.field_at(pts, np.full(40, 5.0)))


def test_field_is_sum_of_its_parts():
    dip = Dipole((1, 1, -1), (2, 0, 1))
    line = DipoleLine((0, 0, -1), (2, 0, -1), (0, 0, 3), 0.1)
    grad = np.array([[0.01, 0, 0], [0, 0.02, 0.03], [0, 0.03, -0.03]])
    origin = np.array([1.0, -1.0, 0.0])
    world = MagneticWorld(
        earth_field=(0.1, 0.2, -0.3),
        dipoles=[dip],
        lines=[line],
        gradient=grad,
        gradient_origin=origin,
        drift_amplitude=0.0,
    )
    p = np.array([[0.5, 0.3, 0.5], [2.0, -1.0, 0.2]])
    expected = (
        np.array([0.1, 0.2, -0.3]) + (p - origin) @ grad.T + dip.field_at(p) + line.field_at(p)
    )
    np.testing.assert_allclose(world.field_at(p), expected, rtol=1e-12)


def test_drift_is_bounded_slow_and_deterministic():
    amplitude = 0.01
    world = MagneticWorld(drift_amplitude=amplitude, drift_period=86400.0)
    t = np.linspace(0, 3 * 86400, 20001)
    drift = world.drift(t)
    magnitude = np.linalg.norm(drift, axis=1)
    assert magnitude.max() <= amplitude * (1 + 1e-12)
    assert magnitude.max() >= 0.999 * amplitude  # the drift is really there
    one_second = np.linalg.norm(world.drift(t + 1.0) - drift, axis=1)
    assert one_second.max() < 0.01 * 0.01  # < 1 % of the 0.01 G noise SD per second
    p = np.zeros((1, 3))
    np.testing.assert_allclose(
        world.field_at(p, 21600.0) - world.field_at(p, 0.0), world.drift([21600.0]), atol=1e-15
    )
    again = MagneticWorld(drift_amplitude=amplitude, drift_period=86400.0).drift(t)
    assert np.array_equal(drift, again)


def test_from_dict_builds_the_scene_and_round_trips():
    d = {
        "earth_field": {"total": 0.46, "inclination_deg": 49.0, "declination_deg": -7.0},
        "dipoles": [{"position": [1, 2, -0.5], "moment": [0, 0, 3]}],
        "lines": [
            {"start": [0, 0, -1], "end": [5, 0, -1], "moment_per_metre": [0, 1, 0], "spacing": 0.5}
        ],
        "gradient": [[0, 0, 0], [0, 0, 0.02], [0, 0.02, 0]],
        "gradient_origin": [1, 1, 0],
        "drift": {"amplitude": 0.005, "period": 3600},
    }
    world = MagneticWorld.from_dict(d, "scene.yaml")
    np.testing.assert_allclose(world.earth_field, earth_field_from_angles(0.46, 49.0, -7.0))
    assert len(world.dipoles) == 1 and len(world.lines) == 1
    assert len(world.lines[0].positions) == 10
    assert world.drift_amplitude == 0.005 and world.drift_period == 3600.0
    pts = np.random.default_rng(0).uniform(-2, 6, (20, 3))
    again = MagneticWorld.from_dict(world.to_dict(), "round trip")
    np.testing.assert_allclose(again.field_at(pts, 100.0), world.field_at(pts, 100.0))
    empty = MagneticWorld.from_dict({}, "empty.yaml")
    np.testing.assert_allclose(empty.field_at(pts), MagneticWorld().field_at(pts))


@pytest.mark.parametrize(
    ("d", "match"),
    [
        ({"earth_feld": [0, 0.3, -0.4]}, r"scene\.yaml: earth_feld: unknown key"),
        (
            {"earth_field": [0, 0.3]},
            r"scene\.yaml: earth_field: must be a list of 3 numbers \[x, y, z\], got \[0, 0\.3\]",
        ),
        (
            {"earth_field": [0, float("nan"), 0]},
            r"scene\.yaml: earth_field\[1\]: must be a finite number, got nan",
        ),
        (
            {"earth_field": {"total": 0.4, "inclination_deg": 40, "dip": 3}},
            r"earth_field\.dip: unknown key",
        ),
        ({"earth_field": {"total": 0.4, "inclination_deg": 95}}, r"inclination_deg: must be"),
        ({"dipoles": [{"position": [0, 0, 0]}]}, r"dipoles\[0\]\.moment: missing"),
        ({"dipoles": [{"position": [0, 0], "moment": [0, 0, 1]}]}, r"dipoles\[0\]\.position"),
        (
            {"dipoles": [{"position": [0, 0, 0], "moment": [0, 0, 1], "mass": 1}]},
            r"dipoles\[0\]\.mass: unknown key",
        ),
        ({"dipoles": {"position": [0, 0, 0]}}, r"dipoles: must be a valid list, got \{'position'"),
        (
            {
                "lines": [
                    {
                        "start": [0, 0, 0],
                        "end": [1, 0, 0],
                        "moment_per_metre": [0, 0, 1],
                        "spacing": -0.1,
                    }
                ]
            },
            r"lines\[0\]\.spacing: must be greater than 0, got -0\.1",
        ),
        (
            {"lines": [{"start": [0, 0, 0], "end": [0, 0, 0], "moment_per_metre": [0, 0, 1]}]},
            r"lines\[0\]\.end: must differ from start \(a zero-length line\), got \[0, 0, 0\]",
        ),
        ({"gradient": [[0, 0, 0], [0, 0, 0]]}, r"gradient: must be a 3 x 3 list of lists"),
        (
            {"drift": {"amplitude": -0.01}},
            r"drift\.amplitude: must be greater than or equal to 0, got -0\.01",
        ),
        (
            {"drift": {"amplitude": 0.01, "period": 0}},
            r"drift\.period: must be greater than 0, got 0",
        ),
        (
            {"drift": {"amplitude": "large"}},
            r"drift\.amplitude: must be a valid number, got 'large'",
        ),
        ({"drift": {"amplitud": 0.01}}, r"drift\.amplitud: unknown key"),
        ({"earth_field": [True, 0, 0]}, r"earth_field\[0\]: must be a valid number, got True"),
        ([1, 2, 3], r"scene\.yaml: must be a mapping of earth_field, .*, got \[1, 2, 3\]"),
    ],
)
def test_from_dict_rejects_bad_scenes(d, match):
    with pytest.raises(ValueError, match=match):
        MagneticWorld.from_dict(d, "scene.yaml")


def test_constructors_reject_bad_values():
    with pytest.raises(ValueError, match="moment"):
        Dipole((0, 0, 0), (0, float("nan"), 0))
    with pytest.raises(ValueError, match="position"):
        Dipole((0, 0), (0, 0, 1))
    with pytest.raises(ValueError, match="radius"):
        Dipole((0, 0, 0), (0, 0, 1), 0.0)
    with pytest.raises(ValueError, match="spacing"):
        DipoleLine((0, 0, 0), (1, 0, 0), (0, 0, 1), -0.5)
    with pytest.raises(ValueError, match="zero length"):
        DipoleLine((1, 0, 0), (1, 0, 0), (0, 0, 1))
    with pytest.raises(ValueError, match="drift_period"):
        MagneticWorld(drift_period=0.0)
    with pytest.raises(ValueError, match="points"):
        MagneticWorld().field_at(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="t: expected shape"):
        MagneticWorld().field_at(np.zeros((4, 3)), np.zeros(3))


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (
            lambda: Dipole((0, 0, 0), (0, 0, 1), 0.0),
            "radius must be a finite number > 0 m, got 0.0",
        ),
        (
            lambda: DipoleLine((0, 0, 0), (1, 0, 0), (0, 0, 1), float("nan")),
            "spacing must be a finite number > 0 m, got nan",
        ),
        (
            lambda: MagneticWorld(drift_period=0.0),
            "drift_period must be a finite number > 0 s, got 0.0",
        ),
        (
            lambda: MagneticWorld(drift_amplitude=-1),
            "drift_amplitude must be a finite number >= 0 G, got -1",
        ),
        (lambda: MagneticWorld(drift_phase=True), "drift_phase must be a finite number, got True"),
        (
            lambda: earth_field_from_angles(0.4, 95, 0),
            "inclination_deg must be a finite number in [-90, 90] deg, got 95",
        ),
        (
            lambda: Magnetometer(quiet_world(), noise_sd=-0.01),
            "noise_sd must be a finite number >= 0 G, got -0.01",
        ),
        (lambda: Magnetometer(quiet_world(), yaw="0"), "yaw must be a finite number, got '0'"),
    ],
)
def test_constructors_word_a_bad_number_as_one_rule(make, message):
    with pytest.raises(ValueError) as e:
        make()
    assert str(e.value) == message


# ------------------------------------------------------------------------------ magnetometer


def test_level_sensor_facing_magnetic_north_and_east():
    world = quiet_world()
    sensor = Magnetometer(world, noise_sd=0.0, self_sources=[])
    b = world.earth_field
    horizontal, down = math.hypot(b[0], b[1]), -b[2]
    north = magnetic_north_heading(world)
    assert math.degrees(north) == pytest.approx(97.5)  # 7.5 deg west of true north (+y)
    facing_north = sensor.read((3.0, -4.0, north))
    np.testing.assert_allclose(facing_north, [horizontal, 0.0, down], atol=1e-12)
    assert facing_north[0] > 0 and facing_north[2] > 0  # x towards north, z down positive
    # facing magnetic east, north is on the robot's left: the sensor's y (right) is negative
    facing_east = sensor.read((0.0, 0.0, north - math.pi / 2))
    np.testing.assert_allclose(facing_east, [0.0, -horizontal, down], atol=1e-12)
    # facing west: north on the right
    facing_west = sensor.read((0.0, 0.0, north + math.pi / 2))
    np.testing.assert_allclose(facing_west, [0.0, horizontal, down], atol=1e-12)
    # general heading: the horizontal part rotates, the vertical one does not
    for heading in np.linspace(-math.pi, math.pi, 13):
        r = sensor.read((0.0, 0.0, heading))
        a = heading - north
        np.testing.assert_allclose(
            r, [horizontal * math.cos(a), horizontal * math.sin(a), down], atol=1e-12
        )


def test_mounting_yaw_and_lever_arm():
    world = quiet_world(dipoles=[Dipole((1.0, 0.0, 0.5), (0.0, 0.0, 2.0))])
    north = magnetic_north_heading(world)
    # a sensor turned +90 deg (facing left) on a robot facing magnetic east faces north
    yawed = Magnetometer(
        quiet_world(), yaw=math.pi / 2, noise_sd=0.0, self_sources=[], mount=(0, 0, 0.3)
    )
    straight = Magnetometer(quiet_world(), noise_sd=0.0, self_sources=[], mount=(0, 0, 0.3))
    np.testing.assert_allclose(
        yawed.read((0, 0, north - math.pi / 2)), straight.read((0, 0, north)), atol=1e-12
    )
    # the mount is a lever arm: sensor at (0.5, 0.2, 0.5) on a robot at (1, -1, 90 deg)
    sensor = Magnetometer(world, mount=(0.5, 0.2, 0.5), noise_sd=0.0, self_sources=[])
    pos = sensor.sensor_positions([[1.0, -1.0, math.pi / 2]])
    np.testing.assert_allclose(pos, [[0.8, -0.5, 0.5]], atol=1e-12)
    reading = sensor.read((1.0, -1.0, math.pi / 2))
    b = world.field_at(pos)[0]
    # robot faces +y: body x = world y, body y (left) = world -x, so the sensor's y (right)
    # is world +x and its z is world -z
    np.testing.assert_allclose(reading, [b[1], b[0], -b[2]], atol=1e-12)


def test_read_many_equals_reads_and_accepts_pose2():
    world = quiet_world(
        dipoles=[Dipole((2, 1, -0.5), (1, 2, 3))], drift_amplitude=0.01, drift_period=100.0
    )
    rng = np.random.default_rng(5)
    poses = np.column_stack([rng.uniform(-3, 3, (30, 2)), rng.uniform(-4, 4, 30)])
    times = rng.uniform(0, 200, 30)
    many = Magnetometer(world, seed=11).read_many(poses, times)
    single = Magnetometer(world, seed=11)
    one_by_one = np.array([single.read(p, t) for p, t in zip(poses, times, strict=True)])
    np.testing.assert_allclose(many, one_by_one, rtol=1e-12)
    quiet = Magnetometer(world, noise_sd=0.0)
    np.testing.assert_allclose(
        quiet.read(Pose2(*poses[0]), times[0]), quiet.expected(poses[0], times[0])
    )


def test_noise_statistics():
    world = quiet_world()
    sensor = Magnetometer(world, noise_sd=0.01, seed=2024)
    pose = (1.0, 2.0, 0.3)
    n = 20000
    readings = sensor.read_many(np.tile(pose, (n, 1)), 0.0)
    truth = sensor.expected(pose)
    sd = readings.std(axis=0, ddof=1)
    np.testing.assert_allclose(sd, 0.01, rtol=0.03)
    assert np.all(np.abs(readings.mean(axis=0) - truth) < 4 * 0.01 / math.sqrt(n))
    # the three axes are independent
    corr = np.corrcoef(readings.T)
    assert np.all(np.abs(corr[np.triu_indices(3, 1)]) < 4 / math.sqrt(n))


def test_noise_is_deterministic_per_seed():
    world = quiet_world()
    poses = np.tile([0.0, 0.0, 0.0], (10, 1))
    a = Magnetometer(world, seed=7).read_many(poses)
    b = Magnetometer(world, seed=7).read_many(poses)
    c = Magnetometer(world, seed=8).read_many(poses)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    assert np.all(np.abs(a - c) > 0)


def test_robot_sources_matter_within_10_cm_and_vanish_by_30_cm():
    # thesis sec. 2.3: low-disturbance devices are negligible beyond 10-15 cm
    world = quiet_world()
    noise = 0.01
    pose = (0.0, 0.0, 0.4)
    directions = [
        np.array(v, float) / np.linalg.norm(v)
        for v in [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (1, -1, 1)]
    ]
    for source in robot_self_sources():
        assert np.linalg.norm(source.moment) == pytest.approx(ROBOT_SOURCE_MOMENT)
        for u in directions:
            effects = {}
            for distance in (0.10, 0.15, 0.30):
                mount = source.position + distance * u
                with_source = Magnetometer(world, mount=mount, noise_sd=0.0, self_sources=[source])
                without = Magnetometer(world, mount=mount, noise_sd=0.0, self_sources=[])
                effects[distance] = np.linalg.norm(with_source.read(pose) - without.read(pose))
            assert effects[0.10] > noise, (source, u, effects)
            assert effects[0.15] < noise, (source, u, effects)
            assert effects[0.30] < noise / 10, (source, u, effects)
    # with the default layout and mount (0, 0, 0.5) the robot's own bias stays below the noise
    bias = Magnetometer(world, noise_sd=0.0).read(pose) - Magnetometer(
        world, noise_sd=0.0, self_sources=[]
    ).read(pose)
    assert 0 < np.linalg.norm(bias) < noise / 2


def test_self_sources_are_a_constant_bias_in_the_sensor_frame():
    world = quiet_world(dipoles=[Dipole((0.5, 0.5, -0.5), (0, 1, 1))])
    sources = [Dipole((0.05, 0.0, 0.4), (0.0, 0.0, 0.02))]
    with_sources = Magnetometer(world, noise_sd=0.0, self_sources=sources)
    without = Magnetometer(world, noise_sd=0.0, self_sources=[])
    poses = np.array([[0, 0, 0], [1, 2, 1.0], [-3, 0.5, -2.5], [0.2, 0.2, 3.0]])
    diff = with_sources.read_many(poses) - without.read_many(poses)
    np.testing.assert_allclose(diff, np.tile(diff[0], (4, 1)), atol=1e-14)
    assert np.linalg.norm(diff[0]) > 0.01


def test_magnetometer_rejects_bad_input():
    world = quiet_world()
    with pytest.raises(ValueError, match="noise_sd"):
        Magnetometer(world, noise_sd=-0.01)
    with pytest.raises(ValueError, match="mount"):
        Magnetometer(world, mount=(0, 0))
    with pytest.raises(ValueError, match="seed"):
        Magnetometer(world, seed=-1)
    with pytest.raises(ValueError, match="world"):
        Magnetometer({"earth_field": [0, 0, 1]})
    sensor = Magnetometer(world)
    with pytest.raises(ValueError, match="robot_pose: must be finite"):
        sensor.read((0.0, float("nan"), 0.0))
    with pytest.raises(ValueError, match="robot_pose"):
        sensor.read((0.0, 0.0))
    with pytest.raises(ValueError, match="poses"):
        sensor.read_many(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="times"):
        sensor.read_many(np.zeros((5, 3)), np.zeros(4))
    with pytest.raises(ValueError, match="times: must be finite"):
        sensor.read_many(np.zeros((2, 3)), [0.0, float("inf")])


# ----------------------------------------------------------------------------------- azimuth


def test_magnetic_azimuth_convention():
    world = quiet_world()
    sensor = Magnetometer(world, noise_sd=0.0, self_sources=[])
    north = magnetic_north_heading(world)
    assert magnetic_azimuth(sensor.read((0, 0, north))) == pytest.approx(0.0, abs=1e-12)
    # facing magnetic east, north is 90 deg to the left: negative (positive = to the right)
    assert magnetic_azimuth(sensor.read((0, 0, north - math.pi / 2))) == pytest.approx(-math.pi / 2)
    headings = np.linspace(-3, 3, 25)
    poses = np.column_stack([np.zeros(25), np.zeros(25), headings])
    az = magnetic_azimuth(sensor.read_many(poses))
    assert az.shape == (25,)
    # the thesis' map quantity theta - m_theta is the same at every heading
    wrapped = np.angle(np.exp(1j * (headings - az - north)))
    np.testing.assert_allclose(wrapped, 0.0, atol=1e-12)
    assert np.all((az >= -math.pi) & (az < math.pi))
    assert magnetic_azimuth([-1.0, 0.0, 0.3]) == pytest.approx(-math.pi)  # [-pi, pi)
    with pytest.raises(ValueError, match="reading"):
        magnetic_azimuth([0.1, float("nan"), 0.3])
