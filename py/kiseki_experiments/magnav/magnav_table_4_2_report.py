# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-table-4-2's claims and notes: Table 4.2's filter columns against the thesis' (its
column without localization is a calibrated number, shown and not claimed), sec. 4.5.1's
statements and Fig. 4.7's ESS."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence
from kiseki_experiments.magnav.magnav_table_4_2_figures import CASES

__all__ = [
    "CALIBRATED",
    "CLAIMS",
    "THESIS_BOUND",
    "THESIS_TABLE",
    "evidence",
    "notes",
    "static_note",
]

#: Table 4.2: case -> (mean, SD) of the travel-distance error, m.
THESIS_TABLE = {"none": (0.678, 0.296), "static": (0.072, 0.061), "dynamic": (0.133, 0.158)}
#: The label of a thesis value that a scene parameter was fitted to (the scene's ``calibrated``).
CALIBRATED = "calibrated, not a result"
#: sec. 4.5.1: "a mean error of 0.2 m or less" with a disturbance every 10 m
THESIS_BOUND = 0.2


TOLERANCE = 0.3
WITHIN = (
    "30 % of the thesis' mean: its own SD over the path is 85-120 % of the mean and its runs' "
    "count is not printed"
)
#: m: the smallest difference between the two fields' errors claimed (a sixth of the thesis'
#: 0.061 m; one reading moves the robot 0.06 m at 0.6 m/s and 10 Hz)
ORDER_MARGIN = 0.01
#: ESS / n: the smallest rise claimed where the field changed (10 of 1000 particles)
ESS_MARGIN = 0.01

ODOMETRY = Control(
    name="the filter off: odometry's travel distance alone",
    overrides=("localize=false",),
    runs=5,
    why="odometry's mean error over the 118 m route is 0.34 m (the scene's tyres, seed SD "
    "0.01 m), far outside every band below",
)
UNCHANGED = Control(
    name="the field unchanged (road plates of no moment)",
    # a short route and few particles: the difference is 0 whatever they are
    overrides=("plate_moment=0.0,0.0,0.0", "length=12.0", "particles=100"),
    runs=5,
    why="the time-varying run then reads the static run's mz (same seed): a difference of 0",
)


def _table(case: str) -> Criterion:
    want = THESIS_TABLE[case][0]
    return Criterion(
        paper_value=f"{want:.3f}",
        compare="within",
        threshold=want,
        tolerance=round(TOLERANCE * want, 4),
        why=WITHIN,
        bounds=(0.0, math.inf),
        paper_number=want,
    )


CLAIMS = (
    ClaimSpec(
        key="static",
        claim="mean travel-distance error, static field (Table 4.2)",
        unit="m",
        criterion=_table("static"),
        control=ODOMETRY,
        measure="mean |estimate - true distance| over one run's readings",
    ),
    ClaimSpec(
        key="dynamic",
        claim="mean travel-distance error, time-varying field (Table 4.2)",
        unit="m",
        criterion=_table("dynamic"),
        control=ODOMETRY,
        measure="mean |estimate - true distance| over one run's readings",
    ),
    ClaimSpec(
        key="order",
        claim="the time-varying field's error exceeds the static field's (Table 4.2)",
        unit="m, time-varying minus static mean error",
        criterion=Criterion(
            paper_value="0.133 - 0.072 = 0.061",
            compare=">=",
            threshold=ORDER_MARGIN,
            why="a sixth of the thesis' 0.061 m; one reading moves 0.06 m at 0.6 m/s, 10 Hz",
        ),
        control=UNCHANGED,
        measure="the run's time-varying minus its static mean error (same seed)",
    ),
    ClaimSpec(
        key="bound",
        claim=f"both filters' mean error under {THESIS_BOUND:g} m (sec. 4.5.1)",
        unit="m, the larger of the two fields' mean errors",
        criterion=Criterion(
            paper_value=f"< {THESIS_BOUND:g}",
            compare="<=",
            threshold=THESIS_BOUND,
            why="the thesis' statement for a field with a disturbance about every 10 m",
            bounds=(0.0, math.inf),
            paper_number=THESIS_BOUND,
        ),
        control=ODOMETRY,
        measure="max(static, time-varying) mean error of the run",
    ),
    ClaimSpec(
        key="ess",
        claim="ESS stays high where the field changed: all weights drop together (Fig. 4.7 A)",
        unit="ESS / n, time-varying minus static",
        criterion=Criterion(
            paper_value="ESS higher in A (10-25 m) with the time-varying field",
            compare=">=",
            threshold=ESS_MARGIN,
            why="a hundredth of n (10 of the 1000 particles) above the static run's",
            bounds=(-1.0, 1.0),
        ),
        control=UNCHANGED,
        measure="mean ESS/n over the readings whose window holds a place of region A, "
        "time-varying minus static (same seed)",
    ),
)


def evidence(config, ok: pd.DataFrame, stretches, change) -> list[Evidence]:
    """Each declared claim's per-trial values (one run's, same seed for the two fields)."""
    where = ", ".join(f"{a:.1f}-{b:.1f} m" for a, b in stretches) or "none"
    changed = (
        f"the field changed at {where}: up to {change['b']:.3f} G on a component, "
        f"{change['mz']:.3f} G on mz, the one the filter reads"
    )
    filt = "" if config.localize else "the filter off (odometry alone); "
    out = []
    for case in ("static", "dynamic"):
        sd = float(ok[f"sd_{case}"].mean())
        out.append(
            Evidence.of(
                case,
                ok[f"mean_{case}"],
                shown=f"SD {sd:.3f} m, thesis {THESIS_TABLE[case][1]:.3f}; end of route "
                f"{float(ok[f'final_{case}'].mean()):.3f} m",
                note=filt + (changed if case == "dynamic" else ""),
            )
        )
    out.append(Evidence.of("order", ok["mean_dynamic"] - ok["mean_static"], note=filt + changed))
    out.append(Evidence.of("bound", np.maximum(ok["mean_static"], ok["mean_dynamic"])))
    dyn, sta = ok["ess_region_a_dynamic"], ok["ess_region_a_static"]
    out.append(
        Evidence.of(
            "ess",
            dyn - sta,
            shown=f"{float(dyn.mean()):.3f} vs {float(sta.mean()):.3f}",
            note=f"{filt}over the readings whose {config.window:g} m window holds a place of "
            f"region A ({config.region_a[0]:g}-{config.region_a[1]:g} m; {changed}); "
            "resamplings there "
            f"{float(ok['resamples_region_a_dynamic'].mean()):.1f} vs "
            f"{float(ok['resamples_region_a_static'].mean()):.1f} per run",
        )
    )
    return out


def static_note(ess: pd.DataFrame) -> str:
    e = ess.set_index("field").loc[CASES["static"]]
    return f"""
Why the static error stays above the thesis' 0.072 m: the weights of eq. 4.8 are nearly even all
along the path (mean ESS/n {e["ess_over_n_elsewhere"]:.3f} outside region A,
{e["resamples_whole_run"]:.1f} resamplings per run): over a 6 m window the reading noise alone
gives every particle s of about 6 m x 0.009 G = 0.05 G m (bins and nodes of 1.7
readings: |N(0, 0.011)| has mean 0.009 G), a s = 2.6, so a pipe's mismatch moves
w by a fraction of itself. The weighted mean of eq. 4.10 then stays near the cloud's mean, which
follows the odometry's over-count between resamplings (Fig. 4.6: the error climbs between the
pipes and is pulled back only in part). a = 50, l and the motion spread are the thesis' or the
filter's documented choices (kiseki.magnetic.travel_distance) and are not tuned here.
"""


def notes(config, stretches, change) -> str:
    where = ", ".join(f"{a:.1f}-{b:.1f} m" for a, b in stretches) or "none"
    plate = (
        f"the playback lattices' moment set to {config.plate_moment} A m^2 by the config "
        "(plate_moment), not the scene's"
        if config.plate_moment
        else "the scene's own plates"
    )
    return f"""
Error: the estimate minus the true distance along the route at each reading (10 Hz, 0.6 m/s);
mean_err_m and sd_err_m are the mean and SD of |error| over one run's readings (Fig. 4.6's
curve as Table 4.2 summarizes it), averaged over the trials; final_err_m is |error| at the
route's end. The thesis does not say whether its table pools the readings of one run or of
several, nor prints its odometry model.

Without localization ({CALIBRATED}): the scene's odometry (header of magnetic_path.yaml)
was fitted so that the error at the end of the 118 m route is the thesis' 0.678 m (final_err_m;
the scene marks both tyre radii as calibrated to it), so no claim compares with that column.
Averaged over the route a steadily growing over-count is about half of its end value. The
thesis' SD/mean of 0.296/0.678 = 0.44 is also below the 0.58 of a linearly growing error: its
odometry error was not a steady scale error, or its table is of another statistic.

Time-varying field: the steel road plates of the scene's playback variant change the field at
{where} (|B_playback - B_teach| > {config.change_threshold} G at the sensor); the thesis' text
places its change at about 10-25 m of travel (Fig. 4.7 A) and prints no size for it (Fig. 4.5
plots it); here {plate}. The largest change on a component is {change["b"]:.4f} G, on mz
{change["mz"]:.4f} G. The filter reads mz only (sec. 3.3.2, see kiseki.magnetic.travel_distance).
The plates lie from the path's centre line to 1.5 m right of it, magnetised in their plane along
y (north): the edge under the path raises mz by about 0.12 G along the whole stretch (plates
centred on the path would change only By there, by symmetry). With plate_moment=0,0,0 the
time-varying run reads the very same mz as the static one (same seed), and the claims that the
change raises the error and the ESS fail (their control); with localize=false the filter's
estimate is replaced by odometry's travel distance, and the claims on the errors fail (theirs).

Filter: {config.particles} particles, a = {config.gain:g}, window l = {config.window:g} m (the
thesis names l without a value: Rahok's 6 m window), motion spread {config.odometry_noise:g} m
per sqrt(m) (eq. 4.6 has no noise term; a particle filter needs one), resampling when ESS <
9n/10. The map: the mapping run's readings (0.01 G noise per axis) averaged per 0.1 m node.
"""
