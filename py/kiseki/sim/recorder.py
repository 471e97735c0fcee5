# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""One robot's record of a run: each time step its ground truth, odometry and every sensor that
is due (lasers see the pedestrians' discs); the latest scan of each laser and the latest reading
of each magnetometer are kept for a controller. Used by kiseki.sim.run."""

from __future__ import annotations

import numpy as np

from kiseki.io.runlog import RunWriter
from kiseki.sim.pedestrians import DiscStamp
from kiseki.sim.pose6 import resting_pose
from kiseki.sim.scene import Scene
from kiseki.sim.setup import RobotSetup, SensorSetup

__all__ = ["Recorder", "planar_pose"]


def planar_pose(p) -> tuple[float, float, float]:
    """(x, y, theta) of a Pose2 or a sequence."""
    return (float(p.x), float(p.y), float(p.theta)) if hasattr(p, "x") else tuple(map(float, p))


MAG_SCHEMA = {
    "type": "object",
    "title": "kiseki.MagneticField",
    "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
}
TILT_SCHEMA = {
    "type": "object",
    "title": "kiseki.TiltScan",
    "properties": {
        "tilt_deg": {"type": "array", "description": "theta < 0 looks down"},
        "scan_deg": {"type": "array"},
        "ranges": {"type": "array", "description": "row-major (tilt, scan); 0 = no return"},
        "gyro_rpy": {"type": "array", "description": "roll, pitch, yaw (rad) with drift"},
        "sensor_pose": {"type": "array"},
    },
}


BEARING_SCHEMA = {
    "type": "object",
    "title": "kiseki.Bearings",
    "properties": {
        "targets": {"type": "array", "items": {"type": "string"}},
        "bearings": {
            "type": "array",
            "description": "rad, counter-clockwise in the sensor frame; null: not seen",
        },
        "elevations": {"type": "array", "description": "rad above the horizontal; null: not seen"},
    },
}


class Recorder:
    """Writes one time step of a robot's ground truth, odometry and every due sensor."""

    def __init__(
        self,
        writer: RunWriter,
        scene: Scene,
        robot: RobotSetup,
        sensors: list[SensorSetup],
        prefix: str,
    ) -> None:
        self.writer, self.scene, self.robot, self.sensors = writer, scene, robot, sensors
        self.prefix = prefix
        self.next_due = {s.name: 0.0 for s in sensors}
        self.latest: dict[str, tuple] = {}  # laser name -> (sensor pose, angles, ranges, max)
        self.readings: dict[str, tuple[float, np.ndarray]] = {}  # magnetometer -> (t, reading G)
        self.grids = {}
        for s in sensors:
            if s.kind == "laser":
                z = s.mount.z
                self.grids[s.name] = scene.ground_truth(z - 0.02, z + 0.02)

    def record(self, t: float, positions: dict[str, tuple[float, float, float]], discs) -> None:
        """Writes step t; `discs`: the pedestrians (x, y, radius) the lasers see."""
        w, p = self.writer, self.prefix
        pose, odom = planar_pose(self.robot.robot.pose), planar_pose(self.robot.odometry.pose)
        w.write_pose(f"{p}/ground_truth", t, pose)
        w.write_transform(
            t, "world", f"{p.strip('/')}/base_link" if p else "base_link", pose, topic=f"{p}/tf"
        )
        w.write_odometry(f"{p}/odom", t, odom)
        for s in self.sensors:
            if t + 1e-9 < self.next_due[s.name]:
                continue
            self.next_due[s.name] = t + s.period
            self._sensor(s, t, pose, positions, discs)

    def _sensor(self, s: SensorSetup, t: float, pose, positions, discs) -> None:
        w, topic = self.writer, f"{self.prefix}/{s.name}"
        if s.kind == "laser":
            if discs:
                with DiscStamp(self.grids[s.name], discs) as grid:
                    sensor_pose, ranges = s.device.scan(grid, pose)
            else:
                sensor_pose, ranges = s.device.scan(self.grids[s.name], pose)
            self.latest[s.name] = (
                sensor_pose,
                s.device.params.angles,
                ranges,
                s.device.params.max_range,
            )
            w.write_laser_scan(
                topic,
                t,
                sensor_pose,
                s.device.params.angles,
                ranges,
                max_range=s.device.params.max_range,
            )
        elif s.kind == "depth_camera":
            w.write_depth_image(topic, t, s.device.render(self.scene.world, pose), s.name)
        elif s.kind == "magnetometer":
            m = s.device.read(pose, t)
            self.readings[s.name] = (t, np.array(m, dtype=np.float64))
            w.write_json(
                topic,
                t,
                "kiseki.MagneticField",
                {"x": float(m[0]), "y": float(m[1]), "z": float(m[2])},
                MAG_SCHEMA,
            )
        elif s.kind == "bearing":
            # the markers sit at the sensor's height on every robot (the scenes are planar)
            planar = s.mount.planar(pose)
            sensor = (planar[0], planar[1], s.mount.z, planar[2])
            targets = np.array([[*positions[n][:2], s.mount.z] for n in s.targets])
            others = np.array([v[:2] for v in positions.values()])
            seen = s.device.observe(sensor, targets, self.scene.world, others)
            w.write_json(
                topic,
                t,
                "kiseki.Bearings",
                {
                    "targets": list(s.targets),
                    "bearings": [
                        float(b) if ok else None
                        for b, ok in zip(seen.bearings, seen.visible, strict=True)
                    ],
                    "elevations": [
                        float(e) if ok else None
                        for e, ok in zip(seen.elevations, seen.visible, strict=True)
                    ],
                },
                BEARING_SCHEMA,
            )
        elif s.kind == "tilting_laser":
            r = self.robot
            body = resting_pose(self.scene.world, pose, r.length, r.width, r.height)
            sensor = s.mount.world(body.values)
            ranges, gyro = s.device.scan(self.scene.world, sensor, t)
            tilt, scan = s.device.params.grid()
            w.write_json(
                topic,
                t,
                "kiseki.TiltScan",
                {
                    "tilt_deg": np.degrees(tilt).tolist(),
                    "scan_deg": np.degrees(scan).tolist(),
                    "ranges": np.nan_to_num(ranges, nan=0.0).ravel().tolist(),
                    "gyro_rpy": gyro.tolist(),
                    "sensor_pose": sensor.ravel().tolist(),
                },
                TILT_SCHEMA,
            )
