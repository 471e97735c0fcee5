# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto-sensors: magnetic-map MCL with both magnetometers of the Aalto robot (InvenSense and
Nexus, Solin et al. 2018's data), as the thesis multiplies its sensors' likelihoods (eq. 6.18),
with and without kiseki's drift check (:mod:`kiseki.magnetic.multi_sensor`).

Each sensor's map is gp-aalto's static map of its own runs 1-4 (:func:`~kiseki_experiments.gp.
gp_aalto_steps.static_map`, with gp-aalto's defaults: the robot-fixed offset removed, one GP per
component), on gp-aalto's MCL grid; the test run is ``test_run`` (5: the Nexus' z reads about
+10 uT there against its runs 1-4). Updates every ``mcl_step`` of travel at the InvenSense's
instants, the Nexus' readings interpolated to them. Trial i: odometry-noise seed i (gp-aalto's
``noisy_odometry``) and filter seed i. Arms: each sensor alone, both trusted throughout, both
with the drift check.

The drift check's statistic where no sensor drifts (table ``in_control``, :func:`in_control`):
each training run 1-4 held out against a map of the other three with the sensor map's
hyperparameters, its readings at the filter's spacing (each sensor at its own instants) less
that map's prediction at the reference positions, over the square root of the prediction's
variance plus the map's noise, the mean over every window of ``window`` updates; per sensor and
axis the largest |mean| and the share of windows past ``limit``: how far below the limit a
sensor that agrees with its map stays. The check itself reads the gridded map of all four runs
at the filter's estimate (the Nexus interpolated to the InvenSense's instants), so the two
statistics are alike, not equal.

Claims (per-seed ratios of the mean position error, a bootstrap interval over the trials):
both sensors with the check are at most half as far off as both trusted throughout (the check
removes what the drifting sensor costs), and at most 1.2x the InvenSense alone (it loses
nothing of the good sensor). Control: ``limit=1000``, a check that never drops, under which
both must fail.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pandas as pd

from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.localization import MagneticMclConfig
from kiseki.magnetic.multi_sensor import DriftCheck, localize_with_magnetometers
from kiseki_experiments.gp import gp_aalto_steps as st
from kiseki_experiments.gp.gp_aalto import GpAaltoConfig, data_dir
from kiseki_experiments.gp.gp_aalto_tasks import bounds, noisy_odometry, travel_subsample
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import Count, Index, Particles, PositiveReal
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = [
    "EXPERIMENT",
    "SensorsConfig",
    "in_control",
    "in_control_windows",
    "maps_and_stream",
    "trial",
    "window_means",
]

SENSORS = ("invensense", "nexus")


@dataclass(frozen=True)
class SensorsConfig:
    data_dir: str = ""  # folder with aalto/; "" = ../shared/data/magnetic
    test_run: Index = 5
    particles: Particles = 1000
    window: Count = DriftCheck.window
    limit: PositiveReal = DriftCheck.limit


def _aalto(config: SensorsConfig) -> GpAaltoConfig:
    return GpAaltoConfig(data_dir=config.data_dir, test_run=config.test_run)


def preflight(config: SensorsConfig) -> None:
    folder = data_dir(_aalto(config)) / "aalto"
    for sensor in SENSORS:
        for run in (1, 2, 3, 4, config.test_run):
            if not (folder / sensor / f"{run}-mag.csv").is_file():
                raise FileNotFoundError(f"gp-aalto-sensors: {folder / sensor}: no run {run}")
    DriftCheck(config.window, config.limit)


def maps_and_stream(config: SensorsConfig):
    """(the two field maps, positions (T, 2), readings (T, 2, 3)) of the test run."""
    return _maps_and_stream(config.data_dir, config.test_run)


@functools.lru_cache(maxsize=2)  # made once a process for the settings they depend on
def _maps_and_stream(folder_setting: str, test_run: int):
    aalto = GpAaltoConfig(data_dir=folder_setting, test_run=test_run)
    folder = data_dir(aalto)
    maps, readings, runs = [], [], {}
    for sensor in SENSORS:
        runs[sensor] = st.load_runs(folder, sensor, [1, 2, 3, 4, test_run])
        sm = st.static_map(aalto, folder, sensor)
        lower, upper = bounds({r: runs[sensor][r] for r in aalto.train_runs}, 0.5)
        gps = sm.gp if isinstance(sm.gp, list) else [sm.gp]
        maps.append(MagneticFieldMap.from_gp(gps, lower, upper, aalto.map_resolution, units="uT"))
        readings.append(sm.corrected(test_run, runs[sensor][test_run]))
    lead = runs[SENSORS[0]][test_run]
    keep = travel_subsample(lead.positions, aalto.mcl_step)
    t = lead.times[keep]
    other = runs[SENSORS[1]][test_run]
    second = np.column_stack([np.interp(t, other.times, readings[1][:, c]) for c in range(3)])
    return maps, lead.positions[keep], np.stack([readings[0][keep], second], axis=1)


def window_means(z: np.ndarray, window: int) -> np.ndarray:
    """The mean of every ``window`` consecutive rows of ``z`` (T, 3): (T - window + 1, 3)."""
    c = np.cumsum(np.vstack([np.zeros(z.shape[1]), z]), axis=0)
    return (c[window:] - c[:-window]) / window


def in_control_windows(config: SensorsConfig) -> dict[str, np.ndarray]:
    """Per sensor: the |window means| (windows, 3) of the normalised innovation on the training
    runs held out in turn, the windows of each run after each other (module text)."""
    aalto = _aalto(config)
    folder = data_dir(aalto)
    out = {}
    for sensor in SENSORS:
        sm = st.static_map(aalto, folder, sensor)
        runs = st.load_runs(folder, sensor, aalto.train_runs)
        kernels = st.kernels_of(sm.gp)
        noise = float(st.sigma_n(kernels).max())  # the filter's map_noise_sd
        train = list(aalto.train_runs)
        fields = {r: sm.corrected(r, runs[r]) for r in train}
        means = []
        for r in train:
            x, y = st.stack_runs(runs, [q for q in train if q != r], fields, aalto.thinning)
            keep = travel_subsample(runs[r].positions, aalto.mcl_step)
            mean, var = st.predict(st.fit_fixed(x, y, kernels), runs[r].positions[keep])
            means.append(
                window_means((fields[r][keep] - mean) / np.sqrt(var + noise**2), config.window)
            )
        out[sensor] = np.abs(np.vstack(means))
    return out


def in_control(config: SensorsConfig, windows: dict | None = None) -> pd.DataFrame:
    """Per sensor and axis: the largest |window mean| and the share of windows past the
    limit, of :func:`in_control_windows` (computed when not given)."""
    windows = in_control_windows(config) if windows is None else windows
    rows = []
    for sensor, m in windows.items():
        for axis in range(3):
            rows.append({
                "sensor": sensor, "axis": "xyz"[axis], "windows": len(m),
                "largest_abs_mean": float(m[:, axis].max()),
                "share_past_limit": float((m[:, axis] > config.limit).mean()),
            })  # fmt: skip
    return pd.DataFrame(rows)


def trial(config: SensorsConfig, index: int, seed: int) -> TrialOutput:
    aalto = _aalto(config)
    maps, xy, z = maps_and_stream(config)
    d = np.diff(xy, axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])
    truth = np.column_stack([xy, np.concatenate([heading[:1], heading])])
    odometry = noisy_odometry(
        truth, np.random.default_rng(seed), aalto.odometry_scale_sd, aalto.heading_walk
    )
    mcl = MagneticMclConfig(particles=config.particles, alphas=tuple(aalto.alphas))
    check = DriftCheck(config.window, config.limit)
    kw = dict(initial_pose=truth[0], config=mcl, seed=seed % 2**63)
    arms = {
        "invensense": localize_with_magnetometers(maps[:1], odometry, z[:, :1], [[0, 0]], **kw),
        "nexus": localize_with_magnetometers(maps[1:], odometry, z[:, 1:], [[0, 0]], **kw),
        "both": localize_with_magnetometers(maps, odometry, z, [[0, 0]] * 2, drift=None, **kw),
        "checked": localize_with_magnetometers(maps, odometry, z, [[0, 0]] * 2, drift=check, **kw),
    }
    record: dict = {
        "updates": len(xy),
        "odometry": float(np.hypot(*(odometry[:, :2] - xy).T).mean()),
    }
    for name, result in arms.items():
        e = np.hypot(*(result.estimates[:, :2] - xy).T)
        record[f"{name}_mean"] = float(e.mean())
        record[f"{name}_max"] = float(e.max())
    drops = arms["checked"].extra["dropped"]
    record["dropped"] = ";".join(
        f"{SENSORS[x.sensor]} at update {x.update}, axis {'xyz'[x.axis]}, mean {x.mean:+.1f}"
        for x in drops
    )
    record["nexus_dropped"] = any(x.sensor == 1 for x in drops)
    return TrialOutput(record, {})


def analyze(config: SensorsConfig, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    table = ok[
        [c for c in ok.columns if c.endswith(("_mean", "_max")) or c in ("odometry", "dropped")]
    ]
    ratio_both = (ok["checked_mean"] / ok["both_mean"]).to_numpy(float)
    ratio_alone = (ok["checked_mean"] / ok["invensense_mean"]).to_numpy(float)
    evidence = [
        Evidence.of(
            "check-removes-the-cost",
            ratio_both,
            shown="per seed " + ", ".join(f"{v:.2f}" for v in ratio_both),
        ),
        Evidence.of(
            "check-keeps-the-good-sensor",
            ratio_alone,
            shown="per seed " + ", ".join(f"{v:.2f}" for v in ratio_alone),
        ),
    ]
    calm = in_control(config)
    largest = ", ".join(
        f"{g} {' / '.join(f'{v:.2f}' for v in part['largest_abs_mean'])}"
        for g, part in calm.groupby("sensor", sort=False)
    )
    past = ", ".join(
        f"{r.sensor} {r.axis} {100 * r.share_past_limit:.1f} %"
        for r in calm.itertuples()
        if r.share_past_limit > 0
    )
    notes = (
        f"Aalto run {config.test_run}, maps of runs 1-4 per sensor; mean / max position error "
        f"(m) per seed; drift check: window {config.window} updates, limit {config.limit}; "
        f"the Nexus was dropped in {int(ok['nexus_dropped'].sum())} of {len(ok)} trials. "
        f"Where no sensor drifts (runs 1-4 held out in turn) the largest |window mean| x / y / z "
        f"is {largest}; windows past the limit: {past or 'none'}"
    )
    tables = {"per_seed": table.reset_index(drop=True), "in_control": calm}
    return Analysis(tables=tables, notes=notes, evidence=evidence)


NEVER_DROPS = Control(
    name="a drift check that never drops a sensor",
    overrides=("limit=1000",),
    runs=5,
    why="both sensors are then trusted throughout, so the drifting one pulls the estimate off",
)

CLAIMS = (
    ClaimSpec(
        key="check-removes-the-cost",
        claim="with the drift check, the two-sensor filter's mean position error is at most half "
        "of the two sensors trusted throughout",
        unit="error ratio",
        criterion=Criterion(
            paper_value="(kiseki's: the thesis trusts its sensors)",
            compare="<=",
            threshold=0.5,
            why="a check that drops the drifting sensor must remove most of what it costs",
            bounds=(0.0, 100.0),
        ),
        control=NEVER_DROPS,
        measure="one seed's mean error with the check over that without it",
    ),
    ClaimSpec(
        key="check-keeps-the-good-sensor",
        claim="with the drift check, the two-sensor filter's mean position error is at most 1.2x "
        "the InvenSense's alone",
        unit="error ratio",
        criterion=Criterion(
            paper_value="(kiseki's)",
            compare="<=",
            threshold=1.2,
            why="after the drop the filter is the good sensor's; the drift before it costs little",
            bounds=(0.0, 100.0),
        ),
        control=NEVER_DROPS,
        measure="one seed's mean error with the check over the InvenSense alone",
    ),
)

EXPERIMENT = Experiment(
    name="gp-aalto-sensors",
    paper="002_74cea16d239c028f.txt",
    artefact="eq. 6.18 with two recorded magnetometers (beyond the thesis)",
    description="magnetic-map MCL with both Aalto magnetometers, with and without a drift check",
    config_type=SensorsConfig,
    trial=trial,
    analyze=analyze,
    # 26: at 5 both claims were undecided; the report asked 26 and 6 trials (284 s)
    # (issue 29: the default trials decide at least 80 % of the claims)
    default_runs=26,
    preflight=preflight,
    claims=CLAIMS,
)
