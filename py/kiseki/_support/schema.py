# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The one typed validation layer for the files kiseki reads (scene YAML, waypoint files, ROS map
YAML, experiment configs, key scripts, command CSVs): pydantic v2 models, checked by
:func:`parse`, whose errors name the file, the field and the value in one line.

Conventions every model follows (so that every file reads the same way):

- models derive from :class:`FileModel` (unknown keys are errors) and use this module's number
  types: strict (a number is not a string, ``true`` is not 1; an int is a float), finite and
  bounded: a float within +-:data:`MAGNITUDE_LIMIT`, an int within int32 (the C++ core's
  ``int``) unless its field says less; every int and float field of a file states its range
  (tests/python/core/test_field_bounds.py walks every model);
- YAML is read with YAML 1.2's numbers (:mod:`kiseki._support.yaml`), so ``5e-2`` is a number;
- everything that sizes memory or time has a limit (``Field(le=...)``) and the limit is in the
  message; seeds are :data:`Seed` (0 <= seed < 2**64, as :func:`kiseki.core.check_seed`);
- a section checked by its own model inside a bigger file passes its location as ``at``
  (``parse(Robot, doc["robots"][0], path, at=("robots", 0))``), so the message shows the whole
  path ``robots[0].sensors[1].rate_hz``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Annotated, Any, TypeVar

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError

from kiseki.core import SEED_RULE, check_seed
from kiseki.errors import KisekiError

__all__ = [
    "INT32_MAX",
    "MAGNITUDE_LIMIT",
    "FileModel",
    "FiniteFloat",
    "NonNegativeFloat",
    "PositiveFloat",
    "PositiveInt",
    "SEED_LIMIT",
    "Seed",
    "SchemaError",
    "location_text",
    "parse",
]

SEED_LIMIT = 2**64
"""Seeds are any integer in [0, 2**64): numpy's and the C++ core's 64-bit generators take them."""

MAGNITUDE_LIMIT = 1e9
"""The largest magnitude of any float in kiseki's files (unless its field says less): no
length (m), time (s), angle (deg), rate or gain of a robot's world comes near (1e9 m is beyond
the Moon, 1e9 s is 30 years), and it keeps the C++ core's doubles (and float32 copies, which
end at 3.4e38) finite through products and squares of such numbers."""
INT32_MAX = 2**31 - 1
"""The largest int of a file (unless its field says less): the C++ core's ``int`` is int32."""

# numbers are strict (``"1.5"`` and ``true`` are not numbers; an int is a float), finite and
# bounded (MAGNITUDE_LIMIT, INT32_MAX)
FiniteFloat = Annotated[
    float,
    Field(strict=True, ge=-MAGNITUDE_LIMIT, le=MAGNITUDE_LIMIT, allow_inf_nan=False),
]
PositiveFloat = Annotated[float, Field(strict=True, gt=0, le=MAGNITUDE_LIMIT, allow_inf_nan=False)]
NonNegativeFloat = Annotated[
    float, Field(strict=True, ge=0, le=MAGNITUDE_LIMIT, allow_inf_nan=False)
]
PositiveInt = Annotated[int, Field(strict=True, gt=0, le=INT32_MAX)]


def _seed(value: Any) -> int:

    if not isinstance(value, int):  # strict: a float or a string in a file is not a seed
        raise ValueError(SEED_RULE)
    try:
        return check_seed(value)
    except ValueError:
        raise ValueError(SEED_RULE) from None


Seed = Annotated[int, BeforeValidator(_seed)]

_M = TypeVar("_M", bound=BaseModel)


class SchemaError(KisekiError, ValueError):
    """A file or config that does not match its model: the message names the file, the field
    and the value. ``errors`` holds every problem found (the message shows the first)."""

    def __init__(self, message: str, errors: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.errors = list(errors) or [message]


class FileModel(BaseModel):
    """Base of the models of kiseki's files: unknown keys are errors, frozen. Use the strict
    number types of this module (a YAML list is accepted where a model says tuple)."""

    model_config = ConfigDict(extra="forbid", frozen=True)


def location_text(loc: Sequence[str | int]) -> str:
    """``("robots", 0, "sensors", 1, "rate_hz")`` -> ``"robots[0].sensors[1].rate_hz"``."""
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _problem(err: dict[str, Any], at: Sequence[str | int]) -> str:
    # pydantic puts the name of a function validator in the location (function-after[...]):
    # only the keys and indices of the document are shown
    loc = [
        p
        for p in (*at, *err.get("loc", ()))
        if isinstance(p, int) or not str(p).startswith("function-")
    ]
    where = location_text(loc)
    message = err.get("msg", "invalid value")
    if message.startswith("Value error, "):
        message = message[len("Value error, ") :]
    if err.get("type") in ("dict_type", "model_type", "dataclass_type"):
        message = "must be a mapping"  # pydantic names the Python class here
    elif message.startswith("Input should be "):
        message = "must be " + message[len("Input should be ") :]
    if err.get("type") == "missing":
        text = "missing"
    elif err.get("type") in ("extra_forbidden", "unexpected_keyword_argument"):
        text = "unknown key"
    else:
        text = f"{message[:1].lower()}{message[1:]}, got {_short(err.get('input'))}"
        value = err.get("input")
        if err.get("type") == "int_type" and isinstance(value, float) and value.is_integer():
            # YAML 1.2 reads 1e9 as a float: say how to write the integer
            text += f" (write it as {int(value)}, without a point or an exponent)"
    return f"{where}: {text}" if where else text


def parse(
    model: type[_M],
    data: Any,
    source: str | os.PathLike[str],
    *,
    at: Sequence[str | int] = (),
) -> _M:
    """``data`` (a parsed YAML document, a CSV row, ...) checked against ``model``; a
    :class:`SchemaError` ``"SOURCE: field.path: problem, got VALUE"`` when it does not match."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        problems = [_problem(e, at) for e in exc.errors(include_url=False)]
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise SchemaError(f"{source}: {problems[0]}{more}", problems) from None
