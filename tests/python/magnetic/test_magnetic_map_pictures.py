# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A magnetic map folder's layer pictures: their scale and offset (value = pixel x scale +
offset, for other tools; kiseki reads the arrays) were read without a look; each is refused in
one line naming the YAML when edited to a value that is not a finite number within bounds."""

from __future__ import annotations

import pytest
import yaml

from _helpers.linear_field_map import linear_map
from kiseki.errors import MapFormatError
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.map_folder import MAP_FILE


@pytest.mark.parametrize(
    ("key", "value", "match"),
    [
        ("scale", float("nan"), r"scale .* must be a finite number in \[0, 2e\+09\], got nan$"),
        ("scale", -0.5, r"scale .* must be a finite number in \[0, 2e\+09\], got -0\.5$"),
        (
            "offset",
            1e300,
            r"offset .* must be a finite number in \[-2e\+09, 2e\+09\], got 1e\+300$",
        ),
        ("offset", "low", r"offset .* must be a finite number in \[-2e\+09, 2e\+09\], got 'low'$"),
        ("offset", None, r"offset \(value = pixel x scale \+ offset\) must be .*, got None$"),
    ],
)
def test_an_edited_picture_scale_is_refused_naming_the_yaml(tmp_path, key, value, match):
    folder = tmp_path / "map"
    linear_map(2).save(folder)
    MagneticFieldMap.load(folder)  # as written: read
    path = folder / MAP_FILE
    doc = yaml.safe_load(path.read_text())
    doc["files"]["layers"]["mz_mean"][key] = value
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(MapFormatError, match=f"layer 'mz_mean': {match}") as caught:
        MagneticFieldMap.load(folder)
    assert str(caught.value).startswith(str(path))
