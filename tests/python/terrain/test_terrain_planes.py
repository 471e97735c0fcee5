# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki terrain planes CLOUD``: plane removal on whole 3-D clouds, checked against planes of
closed form (synthetic clouds), least-squares planes fitted in numpy and the normals stored in
the files (real clouds), and the readers against numpy's own parse of the same files."""

from __future__ import annotations

import bz2
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from kiseki.terrain.cloud_planes import Cloud, cloud_planes, read_cloud

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT.parent / "shared" / "data"
SCAN = DATA / "octomap" / "scan.dat.bz2"
SAC = DATA / "pcd" / "sac_plane_test.pcd"
TABLE = DATA / "pcd" / "table_scene_mug_stereo_textured.pcd"


def need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"{path.name} not found (recorded data)")
    return path


def angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    c = abs(float(np.dot(a, b))) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(min(c, 1.0))))


def lsq_plane(points: np.ndarray) -> np.ndarray:
    """The total-least-squares plane (unit normal, offset) of points, by SVD."""
    centre = points.mean(axis=0)
    normal = np.linalg.svd(points - centre, full_matrices=False)[2][-1]
    return np.append(normal, -normal @ centre)


def same_plane(found: np.ndarray, truth: np.ndarray, deg: float = 1.0, metres: float = 0.01):
    """found and truth as a x + b y + c z + d = 0 with unit normals, up to sign."""
    sign = 1.0 if np.dot(found[:3], truth[:3]) > 0 else -1.0
    return angle_deg(found[:3], truth[:3]) < deg and abs(sign * found[3] - truth[3]) < metres


def synthetic_room(seed: int = 1) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A 4 x 4 m floor (z = 0), a wall x = 2, a ramp z = 0.5 (y - 1) / 1.5 ... as planes of
    known coefficients, and a 0.2 x 0.2 x 0.15 m box on the floor; 3 mm noise."""
    rng = np.random.default_rng(seed)
    g = np.arange(-2.0, 2.0, 0.03)
    u, v = (a.ravel() for a in np.meshgrid(g, g))
    floor = np.c_[u, v, np.zeros_like(u)]
    floor = floor[~((np.abs(floor[:, 0] - 0.5) < 0.1) & (np.abs(floor[:, 1] + 0.5) < 0.1))]
    h = np.arange(0.0, 2.0, 0.03)
    w, z = (a.ravel() for a in np.meshgrid(g, h))
    wall = np.c_[np.full_like(w, 2.0), w, z]
    # a tilted plane: normal n = (0, -1, 3)/sqrt(10) through (0, 3, 1): -y + 3 z = 0
    t, s = (a.ravel() for a in np.meshgrid(g, np.arange(0.0, 1.5, 0.03)))
    ramp = np.c_[t, 2.5 + s * 3 / np.sqrt(10), 0.2 + s / np.sqrt(10)]
    b = np.arange(-0.1, 0.1001, 0.02)
    bx, by = (a.ravel() for a in np.meshgrid(b, b))
    top = np.c_[0.5 + bx, -0.5 + by, np.full_like(bx, 0.15)]
    bz = np.arange(0.01, 0.15, 0.02)
    sides = [np.c_[0.5 + e * 0.1 + 0 * q, -0.5 + q, r] for e in (-1, 1) for q in b for r in bz]
    sides += [np.c_[0.5 + q, -0.5 + e * 0.1 + 0 * q, r] for e in (-1, 1) for q in b for r in bz]
    box = np.vstack([top, *[np.atleast_2d(p) for p in sides]])
    # isolated bumps 5 cm above the floor: on a subset, their nearest point is a floor point
    bumps = np.c_[rng.uniform(-1.9, 0.2, (150, 2)), np.full(150, 0.05)]
    parts = {"floor": floor, "wall": wall, "ramp": ramp, "box": box, "bumps": bumps}
    pts = np.vstack(list(parts.values()))
    pts += rng.normal(0, 0.003, pts.shape)
    truth = {
        "floor": np.array([0, 0, 1, 0.0]),
        "wall": np.array([1, 0, 0, -2.0]),
        "ramp": np.append(np.array([0, -1, 3]) / np.sqrt(10), (2.5 - 3 * 0.2) / np.sqrt(10)),
    }
    return pts, {"truth": truth, "sizes": {k: len(p) for k, p in parts.items()}}


def part_slices(sizes: dict[str, int]) -> dict[str, slice]:
    out, start = {}, 0
    for k, n in sizes.items():
        out[k] = slice(start, start + n)
        start += n
    return out


@pytest.mark.parametrize("max_points", [100_000, 8_000])
def test_synthetic_planes_have_closed_form_coefficients_and_the_box_stays(max_points):
    pts, info = synthetic_room()
    cloud = Cloud(pts, np.zeros(3), 0, "room")
    r = cloud_planes(cloud, "pcl", seed=3, max_points=max_points)
    assert r.fitted == min(len(pts), max_points)
    where = part_slices(info["sizes"])
    for name, truth in info["truth"].items():
        match = [k for k, p in enumerate(r.planes) if same_plane(p, truth)]
        assert match, f"{name} {truth} not among {r.planes.round(3)}"
        # nearly every point of the plane is taken by it
        assert np.mean(r.label[where[name]] == match[0]) > 0.95, name
    box = r.label[where["box"]]
    assert np.mean(box < 0) > 0.9, f"box kept {np.mean(box < 0):.2f}"
    assert np.mean(r.label[where["bumps"]] < 0) > 0.95
    assert abs(r.kept_share - np.mean(r.label < 0)) < 1e-12
    assert r.inliers.sum() == np.sum(r.label >= 0)


def test_hough_removes_a_plane_seen_from_the_sensor_and_not_a_rough_blob():
    rng = np.random.default_rng(5)
    xy = rng.uniform(-3, 3, (30_000, 2))
    floor = np.c_[xy, np.full(len(xy), -0.6)]
    d = rng.normal(size=(20_000, 3))
    blob = d / np.linalg.norm(d, axis=1, keepdims=True) * rng.uniform(1.5, 2.5, (len(d), 1))
    behind = floor[:3000] * 1.3  # seen through the floor (a grate): 18 cm below it
    floor = np.vstack([floor, behind])
    floor_r = cloud_planes(Cloud(floor, np.zeros(3), 0, "floor"), "hough")
    assert np.mean(floor_r.label[-len(behind) :] < 0) > 0.95  # off the plane: kept
    blob_r = cloud_planes(Cloud(blob, np.zeros(3), 0, "blob"), "hough")
    assert floor_r.lines > 0 and np.mean(floor_r.label[: -len(behind)] < 0) < 0.2
    assert blob_r.kept_share > 0.9
    # the origin matters: the same floor seen from a sensor 10 m away is a different S-DEM
    shifted = cloud_planes(Cloud(floor + 5.0, np.full(3, 5.0), 0, "floor"), "hough")
    np.testing.assert_array_equal(shifted.label, floor_r.label)


def test_a_cloud_seen_from_far_off_warns_that_no_line_can_get_its_votes():
    """From an origin 170 m off, a 6 m floor spans a few 1-degree cells of a tilt scan: no
    Hough line can reach its 30 votes. The command took 39 s over accumulators spanning 1.7 km
    and printed '0 lines, kept 100 %' without a word (10 km: 'rho_step is too small'). It
    warns now, and the answer is the Hough's own (checked by running it on the same S-DEM)."""
    from kiseki.terrain.plane_removal import remove_planes
    from kiseki.terrain.sdem import sdem_from_points, sphere_grid

    xy = np.random.default_rng(2).uniform(-3, 3, (5000, 2))
    floor = np.c_[xy, np.full(len(xy), -0.6)]
    origin = np.array([100.0, 100.0, 100.0])
    with pytest.warns(
        UserWarning,
        match=r"^seen from the origin \(100, 100, 100\), the cloud "
        r"spans at most \d cells of one tilt scan, fewer than the 30 a Hough line "
        r"needs: no plane can be found \(is the origin the sensor's position\?\)$",
    ):
        far = cloud_planes(Cloud(floor, origin, 0, "floor"), "hough")
    assert far.lines == 0 and far.kept_share == 1.0
    local = floor - origin
    reach = float(np.max(np.linalg.norm(local, axis=1)))
    grid = sphere_grid((-180.0, 180.0), (-90.0, 90.0), 1.0, 1.01 * reach + 0.01)
    hough = remove_planes(sdem_from_points(local, grid=grid), "hough")
    assert hough.found == 0 and not hough.removed.any()


def test_sac_plane_test_planes_match_least_squares_and_the_files_normals():
    raw = SAC.read_text().split("DATA ascii\n", 1)[1] if need(SAC) else ""
    table = np.loadtxt(raw.splitlines())
    cloud = read_cloud(SAC)
    np.testing.assert_allclose(cloud.points, table[:, :3], atol=1e-6)
    r = cloud_planes(cloud, "pcl", seed=0)
    assert len(r.planes) >= 1 and r.inliers[0] > 0.5 * len(table)
    on = r.label == 0
    assert same_plane(r.planes[0], lsq_plane(table[on, :3]), deg=0.5, metres=0.005)
    normals = table[on, 3:6]
    normals = normals[np.all(np.isfinite(normals), axis=1)]  # the file has NaN normals too
    assert len(normals) > 0.9 * np.sum(on)
    agree = np.abs(normals @ r.planes[0][:3])
    assert np.median(agree) > 0.97, np.median(agree)


def test_table_scene_largest_plane_is_the_table():
    cloud = read_cloud(need(TABLE))
    assert len(cloud.points) == 307_200 - cloud.dropped
    r = cloud_planes(cloud, "pcl", seed=0, max_points=10_000)  # subset: 2 s instead of 35 s
    k = int(np.argmax(r.inliers))
    on = cloud.points[r.label == k]
    assert len(on) > 0.4 * len(cloud.points)
    assert same_plane(r.planes[k], lsq_plane(on), deg=0.5, metres=0.005)
    # the camera (origin) looks down on the table: objects stand on its camera side
    side = cloud.points @ r.planes[k][:3] + r.planes[k][3]
    cam = np.sign(r.planes[k][3])
    kept = r.label < 0
    above = np.sign(side[kept]) == cam
    assert np.mean(np.abs(side[kept][above]) > 0.01) > 0.5


def test_scan_dat_largest_planes_are_the_floor_and_walls():
    cloud = read_cloud(need(SCAN))
    with bz2.open(SCAN, "rt") as f:
        reference = np.array([[float(v) for v in line.split()] for line in f])
    np.testing.assert_array_equal(cloud.points, reference)
    assert len(cloud.points) == 88_206
    r = cloud_planes(cloud, "pcl", seed=0)  # a 20,000-point subset: 4 s instead of 28 s
    order = np.argsort(-r.inliers)
    floor = r.planes[order[0]]
    assert abs(floor[2]) > 0.99
    height = -floor[3] / floor[2]
    assert abs(height - np.percentile(cloud.points[:, 2], 5)) < 0.15
    walls = [r.planes[k] for k in order[1:3]]
    assert walls and all(abs(w[2]) < 0.1 for w in walls)


def test_text_reader_bz2_comments_nan_and_viewpoint(tmp_path):
    pts = np.array([[0.5, -1.0, 2.0], [1e-3, 2.5, -0.25], [np.nan, 1.0, 1.0]])
    text = "# x y z\n\n" + "".join(f"{a:.17g} {b:.17g} {c:.17g}\n" for a, b, c in pts)
    (tmp_path / "c.xyz").write_text(text)
    (tmp_path / "c.xyz.bz2").write_bytes(bz2.compress(text.encode()))
    for name in ("c.xyz", "c.xyz.bz2"):
        c = read_cloud(tmp_path / name)
        np.testing.assert_array_equal(c.points, pts[:2])
        assert c.dropped == 1 and np.all(c.origin == 0)
    pcd = tmp_path / "v.pcd"
    pcd.write_text(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        "VIEWPOINT 1 2 3 1 0 0 0\nPOINTS 2\nDATA ascii\n0.5 -1 2\n1 2 3\n"
    )
    c = read_cloud(pcd)
    np.testing.assert_allclose(c.points, [[0.5, -1, 2], [1, 2, 3]])
    np.testing.assert_array_equal(c.origin, [1, 2, 3])
    np.testing.assert_array_equal(read_cloud(pcd, "0,0,0.5").origin, [0, 0, 0.5])
    wrong = r"--origin must be three numbers x,y,z within \+-1e\+06"
    for bad in ("1,2", "1,2,nan", "a,b,c", "1e300,0,0", "0,-1e7,0", "1_0,0,0"):
        with pytest.raises(ValueError, match=wrong):
            read_cloud(pcd, bad)
    np.testing.assert_array_equal(read_cloud(pcd, "1e6,0,-1e6").origin, [1e6, 0, -1e6])
    # a VIEWPOINT that is not seven finite numbers is refused (it was read as 0, 0, 0, or as
    # its first three numbers when those were finite), unless the origin is given; 3_0 is not
    # a number (float() read it as 30)
    for viewpoint in (
        "nan 2 3 1 0 0 0",
        "1 2 3",
        "1 2 x 1 0 0 0",
        "1 2 3 1 0 0 inf",
        "1 2 3_0 1 0 0 0",
    ):
        pcd.write_text(pcd.read_text().replace("VIEWPOINT 1 2 3 1 0 0 0", f"VIEWPOINT {viewpoint}"))
        with pytest.raises(ValueError, match=rf"v\.pcd: VIEWPOINT '{viewpoint}' is not 7 finite"):
            read_cloud(pcd)
        np.testing.assert_array_equal(read_cloud(pcd, "0,0,1").origin, [0, 0, 1])
        pcd.write_text(pcd.read_text().replace(f"VIEWPOINT {viewpoint}", "VIEWPOINT 1 2 3 1 0 0 0"))
    # a sensor 1e300 m away is refused as --origin refuses it (it overflowed later)
    pcd.write_text(pcd.read_text().replace("VIEWPOINT 1 2 3", "VIEWPOINT 1e300 2 3"))
    with pytest.raises(ValueError, match=r"v\.pcd: VIEWPOINT '1e300 2 3': the sensor lies beyond"):
        read_cloud(pcd)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ("0.5 -1 2\n1 2 3_4\n", "not a number in point 1"),  # read as z = 3
        ("0.5 -1 2\n1 2 3.5abc\n", "not a number in point 1"),  # read as z = 3.5
        ("0.5 -1 2 7\n1 2 3\n", "point 0 has more values than the header's 3"),
    ],
)
def test_ascii_pcd_numbers_end_at_white_space(tmp_path, data, message):
    """The C++ reader's strtod stopped at the first character it could not read and kept the
    number before it."""
    pcd = tmp_path / "a.pcd"
    pcd.write_text(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
        "POINTS 2\nDATA ascii\n" + data
    )
    with pytest.raises(ValueError, match=message) as err:
        read_cloud(pcd)
    assert "a.pcd" in str(err.value)
    pcd.write_text(pcd.read_text().replace(data, "0.5 -1 2\t\r\n1 2 3 \n"))
    np.testing.assert_allclose(read_cloud(pcd).points, [[0.5, -1, 2], [1, 2, 3]])


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "no such file"),
        (b"", "empty cloud"),
        (b"nan nan nan\nnan 1 nan\n", "all 2 points are NaN"),
        (b"1 2 3\n4 5 6\n7 8 x\n", "line 3"),
        (b"1 2 3\n4 5 6 7\n", "line 2"),
        # PEP 515 underscores are not numbers (the line-by-line reader's float() read 5_0 as 50)
        (b"1 2 3\n4 5 6\n4 5_0 6\n", r"line 3: .*'4 5_0 6' \('5_0' is not a number\)"),
        (b"\x89PNG\r\n\x1a\n\x00\xff\xfe", "not a point cloud"),
        (b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n", "PCD"),
        # beyond float, PCL's search aborted the process (SIGABRT) on these
        (b"1 2 3\n1e39 1 2\n4 5 6\n", "point 2 of the finite ones, .* lies beyond \\+-1e\\+06 m"),
        (b"1 2 3\n4 5 1e300\n", "point 2 of the finite ones"),
    ],
)
def test_bad_clouds_name_the_file_and_problem(tmp_path, content, message):
    path = tmp_path / "bad.txt"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(ValueError, match=message) as err:
        read_cloud(path)
    assert str(path) in str(err.value)
    if content is None or message not in ("line 3", "not a point cloud"):
        return  # the command's one line for two of them (each run starts Python: 2 s)
    run = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "terrain", "planes", str(path), "-o",
         str(tmp_path / "o.png")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert run.returncode == 1, run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and message.split()[0] in run.stderr
    assert not (tmp_path / "o.png").exists()


def test_cli_writes_the_planes_csv_and_picture(tmp_path):
    pts, info = synthetic_room()
    pts = pts[::3]  # a lighter cloud: the command's run is mostly Python's start and the picture
    src = tmp_path / "room.xyz.bz2"
    src.write_bytes(bz2.compress("".join(f"{a} {b} {c}\n" for a, b, c in pts).encode()))
    out, csv = tmp_path / "room.png", tmp_path / "planes.csv"
    run = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "terrain", "planes", str(src), "-o", str(out),
         "--csv", str(csv), "--seed", "3", "--max-points", "8000"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = csv.read_text().splitlines()
    assert lines[0] == "plane,a,b,c,d,inliers"
    rows = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    for truth in info["truth"].values():
        assert any(same_plane(row[1:5], truth) for row in rows)
    kept = len(pts) - rows[:, 5].sum()
    assert f"kept {int(kept)} ({100 * kept / len(pts):.1f} %)" in run.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "terrain", "planes", str(src), "-o", str(out),
         "--method", "ransac"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert bad.returncode == 1 and "--method" in bad.stderr
    nowhere = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "terrain", "planes", str(src), "-o", str(out),
         "--csv", str(tmp_path / "no" / "p.csv")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert nowhere.returncode == 1 and "--csv" in nowhere.stderr and not nowhere.stdout
