# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated magnetic field and a 3-axis magnetometer.

The field model follows the facts of the magnetic-navigation thesis
(``002_74cea16d239c028f.txt``, Japanese original, chapter 2, pp. 13-24; English digest in
``DIGEST.md``):

* the Earth's field, spatially uniform over a robot's workspace;
* **steel** (beams, pipes, rebar, manholes) as permanent point dipoles (:class:`Dipole`) or
  rows of them (:class:`DipoleLine`): the "local peak" disturbances of thesis Fig. 2.7;
* a linear **gradient** about a reference point: the "cross-track gradient" disturbances of
  thesis Fig. 2.8;
* a slow **temperature drift**: the thesis (sec. 2.2, Figs. 2.1-2.4) finds that readings drift
  with temperature and humidity but that the steel disturbances are much larger than the drift;
* the robot's **own** motors, battery and PC as dipoles fixed in the body frame, whose effect the
  thesis (sec. 2.3, Fig. 2.6) finds negligible beyond 10-15 cm for low-disturbance devices.

Units: gauss (G; 1 G = 1e-4 T = 100 uT) for fields, metres, seconds, radians, A m^2 for dipole
moments. Frames:

* **world**: x east, y north, z up (ENU, as ROS REP-103); headings counter-clockwise from +x;
* **body** of the robot: x forward, y left, z up, origin on the floor (the robot is planar and
  level, pose ``(x, y, theta)``);
* **sensor**: x forward, y right, z down, the thesis' convention for its MicroStrain 3DM-DH
  (sec. 2.2 and sec. 3.3.1: "x = direction of travel, y = 90 deg to the right, z = towards the
  ground"). The sensor frame is the body frame turned by the mounting yaw and then by pi about
  its x axis, so y and z change sign.

All randomness comes from :class:`kiseki.core.Random`; give each sensor its own stream with
``kiseki.derive_seed(seed, k)``.

The world's field is :mod:`kiseki.sim.magnetic_world`, the magnetometer
:mod:`kiseki.sim.magnetometer` and the dipoles :mod:`kiseki.sim.dipoles`; this module gathers
the names of its ``__all__`` from them (the import path the library, the experiments and users
have used). The rebar lattice is :mod:`kiseki.sim.magnetic_lattice`, the scene section's schema
:mod:`kiseki.sim.magnetic_schema`.
"""

from __future__ import annotations

from kiseki.sim.dipoles import (
    DEFAULT_DIPOLE_RADIUS,
    MU0_OVER_4PI_GAUSS,
    Dipole,
    DipoleLine,
    dipole_field,
)
from kiseki.sim.magnetic_world import (
    DEFAULT_DECLINATION_DEG,
    DEFAULT_DRIFT_AMPLITUDE,
    DEFAULT_DRIFT_PERIOD,
    DEFAULT_EARTH_TOTAL,
    DEFAULT_INCLINATION_DEG,
    MagneticWorld,
    default_earth_field,
    earth_field_from_angles,
)
from kiseki.sim.magnetometer import (
    DEFAULT_MOUNT,
    DEFAULT_NOISE_SD,
    ROBOT_SOURCE_MOMENT,
    Magnetometer,
    magnetic_azimuth,
    robot_self_sources,
)

__all__ = [
    "DEFAULT_DECLINATION_DEG",
    "DEFAULT_DIPOLE_RADIUS",
    "DEFAULT_DRIFT_AMPLITUDE",
    "DEFAULT_DRIFT_PERIOD",
    "DEFAULT_EARTH_TOTAL",
    "DEFAULT_INCLINATION_DEG",
    "DEFAULT_MOUNT",
    "DEFAULT_NOISE_SD",
    "MU0_OVER_4PI_GAUSS",
    "ROBOT_SOURCE_MOMENT",
    "Dipole",
    "DipoleLine",
    "MagneticWorld",
    "Magnetometer",
    "default_earth_field",
    "dipole_field",
    "earth_field_from_angles",
    "magnetic_azimuth",
    "robot_self_sources",
]
