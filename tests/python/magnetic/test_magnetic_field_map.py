# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic field maps: the folder round trip, interpolation against closed forms, the prior
outside, OctoMap's voxel layout (liboctomap through kiseki's octree bindings), bad folders."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from _helpers.linear_field_map import KERNEL, linear_field, linear_map
from kiseki import _core
from kiseki.errors import MapFormatError
from kiseki.gp import ExactGP, SquaredExponential
from kiseki.io.ros_map import read_image
from kiseki.magnetic import map_gp as map_gp_module
from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData
from kiseki.magnetic.map_folder import MAP_FILE


@pytest.mark.parametrize("dimension", [2, 3])
def test_save_load_round_trip_is_exact(tmp_path, dimension):
    rng = np.random.default_rng(dimension)
    fmap = linear_map(dimension)
    noisy = MagneticFieldMap(
        origin=fmap.origin,
        resolution=fmap.resolution,
        mean=fmap.mean + rng.normal(0, 1e-7, fmap.mean.shape),  # digits a PNG would lose
        variance=fmap.variance,
        prior_mean=fmap.prior_mean,
        prior_variance=fmap.prior_variance,
        kernel=(KERNEL, SquaredExponential(1.0, 0.3, 0.2), KERNEL),
        units="uT",
        height=fmap.height,
        provenance=fmap.provenance,
        training=fmap.training,
    )
    noisy.save(tmp_path / "map")
    back = MagneticFieldMap.load(tmp_path / "map")
    for name in ("origin", "mean", "variance", "prior_mean", "prior_variance"):
        np.testing.assert_array_equal(getattr(back, name), getattr(noisy, name))
    assert back.resolution == noisy.resolution and back.kernel == noisy.kernel
    assert (back.units, back.height, back.dimension) == ("uT", noisy.height, dimension)
    assert back.provenance["data"] == {"sources": ["run/1"], "points": 12}
    np.testing.assert_array_equal(back.training.inputs, noisy.training.inputs)
    np.testing.assert_array_equal(back.training.outputs, noisy.training.outputs)
    doc = yaml.safe_load((tmp_path / "map" / MAP_FILE).read_text())
    assert (doc["kind"], doc["dimension"], doc["frame"]) == (
        "magnetic_field_map",
        dimension,
        "world",
    )
    assert doc["shape"] == dict(zip("xyz", (7, 5, 4)[:dimension], strict=False))
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left


def test_layer_images_are_16_bit_pngs_with_the_top_row_at_the_highest_y(tmp_path):
    fmap = linear_map(2)
    fmap.save(tmp_path / "map")
    doc = yaml.safe_load((tmp_path / "map" / MAP_FILE).read_text())
    for k, component in enumerate(("mx", "my", "mz")):
        for quantity in ("mean", "variance"):
            entry = doc["files"]["layers"][f"{component}_{quantity}"]
            image = read_image(tmp_path / "map" / entry["image"])
            assert image.dtype == np.uint16 and image.shape == (5, 7)
            decoded = entry["offset"] + entry["scale"] * image.astype(float)
            layer = getattr(fmap, quantity)[..., k]
            np.testing.assert_allclose(decoded[::-1], layer, rtol=0, atol=entry["scale"] * 0.51)
            assert image.max() == 65535 and image.min() == 0  # the full 16-bit range used


@pytest.mark.parametrize("dimension", [2, 3])
def test_interpolation_matches_a_linear_field_and_the_prior_outside(dimension):
    fmap = linear_map(dimension)
    rng = np.random.default_rng(7)
    first = fmap.origin + 0.5 * fmap.resolution  # the cell centres' hull
    last = fmap.upper - 0.5 * fmap.resolution
    inside = rng.uniform(first, last, (500, dimension))
    mean, var = fmap.value_at(inside)
    expected_mean, expected_var = linear_field(inside)
    np.testing.assert_allclose(mean, expected_mean, rtol=0, atol=1e-12)
    np.testing.assert_allclose(var, expected_var, rtol=0, atol=1e-12)
    # the outer half cell keeps the edge cells' values: the closed form at the clamped point
    rim = rng.uniform(fmap.lower, fmap.upper, (200, dimension))
    np.testing.assert_allclose(
        fmap.value_at(rim)[0], linear_field(np.clip(rim, first, last))[0], atol=1e-12
    )
    outside = np.vstack([fmap.lower - 1e-9, fmap.upper + np.r_[0.01, np.zeros(dimension - 1)]])
    mean, var = fmap.value_at(outside)
    np.testing.assert_array_equal(mean, np.tile(fmap.prior_mean, (2, 1)))
    np.testing.assert_array_equal(var, np.tile(fmap.prior_variance, (2, 1)))
    edge = fmap.value_at(fmap.upper[None])[0]  # the upper corner is still on the map
    np.testing.assert_allclose(edge, linear_field(last[None])[0], atol=1e-12)
    with pytest.raises(ValueError, match=rf"shape \(m, {dimension}\)"):
        fmap.value_at(np.zeros((2, 5 - dimension)))
    with pytest.raises(ValueError, match="finite"):
        fmap.value_at(np.full((1, dimension), np.nan))


def test_a_map_one_cell_thick_interpolates_along_its_other_axes():
    fmap = linear_map(3, cells=(4, 3, 1))
    p = np.array([[-0.5, 2.4, 0.55], [-0.2, 2.6, 0.74]])
    clamped = p.copy()
    clamped[:, 2] = 0.625  # the single layer's centre
    np.testing.assert_allclose(fmap.value_at(p)[0], linear_field(clamped)[0], atol=1e-12)


def small_gp(dimension: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-1, 1, (40, dimension))
    y = np.column_stack([np.sin(2 * x[:, 0]), np.cos(x[:, 1]), x.sum(axis=1)])
    return ExactGP.fit(x, y, KERNEL), x, y


def test_from_gp_evaluates_the_gp_on_octomap_aligned_cells(monkeypatch):
    gp, _, _ = small_gp(3)
    monkeypatch.setattr(map_gp_module, "_CHUNK", 7)  # several chunks
    fmap = MagneticFieldMap.from_gp(gp, [-0.33, 0.12, -0.05], [0.4, 0.5, 0.25], 0.1)
    np.testing.assert_allclose(fmap.origin, [-0.4, 0.1, -0.1], atol=1e-12)
    assert fmap.cells == (8, 4, 4)
    assert np.all(fmap.lower <= [-0.33, 0.12, -0.05]) and np.all(fmap.upper >= [0.4, 0.5, 0.25])
    mean, var = gp.predict(fmap.cell_centres())
    np.testing.assert_allclose(fmap.mean.reshape(-1, 3), mean, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(fmap.variance.reshape(-1, 3), np.maximum(var, 0), atol=1e-12)
    np.testing.assert_allclose(fmap.prior_mean, gp.prior_mean)
    np.testing.assert_allclose(fmap.prior_variance, [KERNEL.sigma_f**2] * 3)
    # cell (i, j, k) centre = origin + ((i, j, k) + 0.5) * resolution, x fastest in memory
    np.testing.assert_allclose(fmap.cell_centres()[8 * 4 + 8 + 1], [-0.25, 0.25, 0.05], atol=1e-12)
    assert list(fmap.octomap_key_origin()) == [32764, 32769, 32767]
    gp2, _, _ = small_gp(2)  # cell indices past int64 wrapped: a 1 x 1 map at 1e-300 m
    for lower, upper, resolution in (([0, 0], [1, 1], 1e-300), ([-1e300, 0], [1e300, 1], 0.1)):
        with pytest.raises(ValueError, match="beyond any grid's cell indices"):
            MagneticFieldMap.from_gp(gp2, lower, upper, resolution)
    # 2**32 x 2**32 cells: their int64 product wrapped to 0 and passed the cell limit
    with pytest.raises(ValueError, match="more than 20,000,000"):
        MagneticFieldMap.from_gp(gp2, [0, 0], [2.0**32, 2.0**32], 1.0)
    for resolution, shown in ((0.0, "0.0"), (np.nan, "nan"), (True, "True")):  # True was 1 m
        with pytest.raises(
            ValueError, match=rf"^resolution must be a finite number > 0 m, got {shown}$"
        ):
            MagneticFieldMap.from_gp(gp2, [0, 0], [1, 1], resolution)


def test_voxel_centres_are_octomap_key_centres():
    """liboctomap (through kiseki's OctreeWorld) marks the voxel holding a point: its centre
    must be the centre of the map's voxel holding that point, at the same resolution."""
    fmap = linear_map(3, cells=(6, 5, 4), origin=(-0.3, -0.2, -0.1), resolution=0.1)
    rng = np.random.default_rng(3)
    centres = fmap.cell_centres()
    for index in rng.choice(len(centres), 6, replace=False):
        point = centres[index] + rng.uniform(-0.4, 0.4, 3) * fmap.resolution
        world = _core.BoxWorld(point[None], np.full((1, 3), 1e-4), np.eye(3)[None])
        tree = _core.OctreeWorld.from_boxes(world, fmap.resolution)
        assert tree.occupied_leaves == 1
        lo, hi = tree.bounds
        np.testing.assert_allclose((lo + hi) / 2, centres[index], atol=1e-6)  # floats inside
        np.testing.assert_allclose(hi - lo, fmap.resolution, atol=1e-6)


def test_a_2d_slice_of_a_3d_gp_and_exact_predictions():
    gp, x, y = small_gp(3, seed=1)
    training = TrainingData(x, y)
    fmap = MagneticFieldMap.from_gp(gp, [-1, -1], [1, 1], 0.2, height=0.3, training=training)
    assert fmap.dimension == 2 and fmap.height == 0.3
    at = np.column_stack([fmap.cell_centres(), np.full(fmap.mean.size // 3, 0.3)])
    np.testing.assert_allclose(fmap.mean.reshape(-1, 3), gp.predict(at)[0], atol=1e-12)
    points = np.array([[0.13, -0.41], [2.5, 0.0]])  # the second off the map
    mean, var = fmap.predict(points)
    expected = gp.predict(np.column_stack([points, [0.3, 0.3]]))
    np.testing.assert_allclose(mean, expected[0], atol=1e-9)
    np.testing.assert_allclose(var, np.maximum(expected[1], 0), atol=1e-9)
    with pytest.raises(ValueError, match="height"):
        MagneticFieldMap.from_gp(gp, [-1, -1], [1, 1], 0.2)


def test_bad_maps_are_refused():
    good = linear_map(2)
    fields = dict(
        origin=good.origin,
        resolution=0.25,
        mean=good.mean,
        variance=good.variance,
        prior_mean=good.prior_mean,
        prior_variance=good.prior_variance,
        kernel=KERNEL,
    )
    nan = good.mean.copy()
    nan[1, 2, 0] = np.nan
    for change, match in [
        ({"mean": nan}, "mean must be finite"),
        ({"variance": -good.variance}, "variance must be >= 0"),
        ({"variance": good.variance[:, :3]}, "variance must have shape"),
        ({"origin": [0.0, 0.0, 0.0]}, "origin must have shape"),
        ({"resolution": 0.0}, r"^resolution must be a finite number > 0 m, got 0.0$"),
        ({"resolution": np.inf}, r"^resolution must be a finite number > 0 m, got inf$"),
        ({"height": np.nan}, r"^height must be a finite number \(m\), got nan$"),
        ({"height": "0.2"}, r"^height must be a finite number \(m\), got '0.2'$"),  # was 0.2 m
        ({"height": True}, r"^height must be a finite number \(m\), got True$"),  # was 1 m
        ({"mean": good.mean[..., :2]}, "mean must have shape"),
        ({"kernel": "se"}, "kernel"),
        ({"prior_variance": [1.0, 0.0, 1.0]}, "prior_variance"),
    ]:
        with pytest.raises(ValueError, match=match):
            MagneticFieldMap(**{**fields, **change})


def _edit_yaml(folder, **changes):
    path = folder / MAP_FILE
    doc = yaml.safe_load(path.read_text())
    doc.update(changes)
    path.write_text(yaml.safe_dump(doc))


def _nan_layer(folder, value=np.nan):
    with np.load(folder / "layers.npz") as npz:
        arrays = dict(npz)
    arrays["my_variance"][0, 0] = value
    np.savez(folder / "layers.npz", **arrays)


def _cut_in_half(path):
    """A zip cut short, as a copy or download that stopped: its magic is a zip's."""
    data = path.read_bytes()
    assert data[:2] == b"PK" and len(data) > 200
    path.write_bytes(data[: len(data) // 2])


@pytest.mark.parametrize(
    ("spoil", "culprit", "match"),
    [
        (lambda f: (f / MAP_FILE).unlink(), MAP_FILE, "not a magnetic field map"),
        (
            lambda f: _edit_yaml(f, kind="occupancy_grid"),
            MAP_FILE,
            "kind: must be 'magnetic_field_map', got 'occupancy_grid'",
        ),
        (lambda f: (f / MAP_FILE).write_bytes(b"\x89\xff\x00"), MAP_FILE, "not UTF-8"),
        (lambda f: (f / "mz_variance.png").unlink(), "mz_variance.png", "missing"),
        (lambda f: (f / "layers.npz").unlink(), "layers.npz", "missing"),
        (lambda f: _edit_yaml(f, shape={"x": 7, "y": 6}), "mx_mean.png", "the YAML says"),
        (lambda f: _nan_layer(f), "layers.npz", "NaN"),
        # finite but past the +-1e9 every number in a file keeps to: rendered before
        (lambda f: _nan_layer(f, 1e300), "layers.npz", "'my_variance' holds 1e\\+300, beyond"),
        (lambda f: (f / "training.npz").write_text("x"), "training.npz", "not a readable"),
        (lambda f: _cut_in_half(f / "layers.npz"), "layers.npz", "not a readable"),
        (lambda f: _edit_yaml(f, dimension=4), MAP_FILE, "dimension: must be 2 or 3, got 4"),
    ],
)
def test_bad_folders_are_refused_naming_the_file(tmp_path, spoil, culprit, match):
    folder = tmp_path / "map"
    linear_map(2).save(folder)
    spoil(folder)
    with pytest.raises(MapFormatError, match=match) as caught:
        MagneticFieldMap.load(folder)
    assert str(caught.value).startswith(str(folder / culprit))


def test_a_cut_layer_image_is_refused_without_the_codecs_own_lines(tmp_path, capfd):
    """libpng printed "libpng warning: ..." and "libpng error: Read Error" on stderr before
    the layer's error: kiseki's one line became three."""
    folder = tmp_path / "map"
    linear_map(2).save(folder)
    image = folder / "mx_mean.png"
    whole = image.read_bytes()
    capfd.readouterr()
    for cut in (whole[:60], whole[:-1], whole[:8] + b"x" * 50):
        image.write_bytes(cut)
        with pytest.raises(MapFormatError, match="a truncated PNG") as caught:
            MagneticFieldMap.load(folder)
        assert str(caught.value).startswith(f"{image}: unreadable layer image")
        assert capfd.readouterr().err == ""
    image.write_bytes(whole + b"trailing bytes")  # after IEND: read as before
    np.testing.assert_array_equal(MagneticFieldMap.load(folder).mean, linear_map(2).mean)


@pytest.mark.parametrize(
    ("dimension", "changes", "problem"),
    [
        (
            2,
            {"shape": {"x": 99_999_999, "y": 6}},
            "shape.x: must be less than or equal to 10000000, got 99999999",
        ),
        (
            2,
            {"shape": {"x": 5000, "y": 5000}},
            "shape: at most 10,000,000 cells in all (here 25,000,000), got {'x': 5000, 'y': 5000}",
        ),
        (
            3,
            {"shape": {"x": 1000, "y": 1000, "z": 11}},
            "shape: at most 10,000,000 cells in all (here 11,000,000)",
        ),
        (2, {"shape": {"x": 7, "y": True}}, "shape.y: must be a valid integer, got True"),
        (
            3,
            {"shape": {"x": 7, "y": 5}},
            "shape: must give the cell counts of x, y, z, got {'x': 7, 'y': 5}",
        ),
        (2, {"resolution": float("nan")}, "resolution: must be a finite number, got nan"),
        (
            2,
            {"origin": [0.0, 1.0, 2.0]},
            "origin: must be a list of 2 numbers (the map is 2-D), got [0.0, 1.0, 2.0]",
        ),
        (
            2,
            {"prior_variance": [1.0, "a", 1.0]},
            "prior_variance[1]: must be a valid number, got 'a'",
        ),
        (
            2,
            {"kernel": {"sigma_f": 1.0, "length_scale": -2.0, "sigma_n": 0.1}},
            "kernel.length_scale: must be greater than 0, got -2.0",
        ),
        (2, {"format_version": 2}, "format_version: must be 1, got 2"),
        (2, {"colour": "red"}, "colour: unknown key"),
    ],
)
def test_a_hand_edited_description_is_refused_naming_the_field_and_value(
    tmp_path, dimension, changes, problem
):
    """magnetic_map.yaml is read through its model (kiseki.magnetic.map_doc): the cell counts
    are limited before any array is read."""
    folder = tmp_path / "map"
    linear_map(dimension).save(folder)
    _edit_yaml(folder, **changes)
    with pytest.raises(MapFormatError) as caught:
        MagneticFieldMap.load(folder)
    assert str(caught.value).startswith(f"{folder / MAP_FILE}: {problem}"), str(caught.value)
    assert "\n" not in str(caught.value)


def test_3d_voxels_that_disagree_with_the_yaml_are_refused(tmp_path):
    folder = tmp_path / "voxels"
    fmap = linear_map(3)
    fmap.save(folder)
    np.savez(
        folder / "voxels.npz",
        mean=fmap.mean,
        variance=fmap.variance[:-1],
        origin=fmap.origin,
        resolution=fmap.resolution,
    )
    with pytest.raises(MapFormatError, match=r"voxels.npz: 'variance' has shape \(3, 5, 7, 3\)"):
        MagneticFieldMap.load(folder)


def test_saving_replaces_a_map_but_never_another_folder(tmp_path):
    fmap = linear_map(2)
    fmap.save(tmp_path / "map")
    linear_map(3).save(tmp_path / "map")  # a map folder is replaced whole
    assert MagneticFieldMap.load(tmp_path / "map").dimension == 3
    assert not (tmp_path / "map" / "layers.npz").exists()
    (tmp_path / "map" / "notes.txt").write_text("mine")  # replaced whole: it would go with it
    with pytest.raises(FileExistsError, match="map holds notes.txt, which is not part of a mag"):
        fmap.save(tmp_path / "map")
    assert (tmp_path / "map" / "notes.txt").read_text() == "mine"
    (tmp_path / "map" / "notes.txt").unlink()
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "cat.jpg").write_bytes(b"meow")
    with pytest.raises(FileExistsError, match="not a magnetic field map folder"):
        fmap.save(tmp_path / "photos")
    assert (tmp_path / "photos" / "cat.jpg").read_bytes() == b"meow"
    with pytest.raises(FileNotFoundError, match="does not exist"):
        fmap.save(tmp_path / "no" / "map")
    with pytest.raises(FileNotFoundError, match="no such magnetic field map folder"):
        MagneticFieldMap.load(tmp_path / "absent")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map", "photos"]


def test_a_reduced_rank_map_rebuilds_each_component_s_gp_on_its_own_box():
    """Three kernels of different length scales, one reduced-rank GP each, each on the default
    box its length scale sets: what a map keeps of them (hilbert_settings) rebuilds the same
    GPs, bit for bit. Control: one box for every GP (the first's, as maps kept before) moves
    the third component by more than 1e-3 (its noise SD is 0.05)."""
    rng = np.random.default_rng(0)
    x = rng.uniform(0.0, 6.0, (600, 2))
    y = np.c_[np.sin(x[:, 0]), np.cos(x[:, 1]), np.sin(x[:, 0] + x[:, 1])]
    y = y + rng.normal(0.0, 0.05, y.shape)
    kernels = [SquaredExponential(1.0, ell, 0.05) for ell in (0.4, 0.8, 1.5)]
    gps = map_gp_module.fit_component_gps(x, y, kernels, "hilbert")
    assert len({tuple(g.lower) for g in gps}) == 3  # three boxes
    q = rng.uniform(0.0, 6.0, (50, 2))
    fitted = map_gp_module.predict_all(gps, q)
    kept = TrainingData(x, y, "hilbert", "constant", map_gp_module.hilbert_settings(gps))
    rebuilt = map_gp_module.predict_all(map_gp_module.rebuild(kept, kernels), q)
    assert all(np.array_equal(a, b) for a, b in zip(rebuilt, fitted, strict=True))
    box = [gps[0].lower.tolist(), gps[0].upper.tolist()]
    one_box = {"domain": box, "tolerance": [g.tolerance for g in gps]}
    older = TrainingData(x, y, "hilbert", "constant", one_box)
    moved = map_gp_module.predict_all(map_gp_module.rebuild(older, kernels), q)[0] - fitted[0]
    assert np.abs(moved[:, 2]).max() > 1e-3
